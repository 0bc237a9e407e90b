// piezobench.fem: include/piezobench/fem/{superelement,structural_model,matrix_io,craig_bampton}.hpp
#include "common.hpp"
#include "described.hpp"
#include "piezobench/fem/craig_bampton.hpp"
#include "piezobench/fem/matrix_io.hpp"
#include "piezobench/fem/structural_model.hpp"
#include "piezobench/fem/superelement.hpp"
#include "piezobench/lti/state_space.hpp"

namespace piezobench::python {
namespace {

using namespace piezobench::fem;

const Options<ImportOptions>& import_options() {
  static const Options<ImportOptions> t = [] {
    Options<ImportOptions> o("ImportOptions");
    o.add("symmetry_tolerance", &ImportOptions::symmetry_tolerance, "relative asymmetry accepted in K and M")
        .add("check_rigid_body_modes", &ImportOptions::check_rigid_body_modes, "warn when the rigid-body modes are spoiled")
        .add("max_dense_size", &ImportOptions::max_dense_size, "largest dense model read");
    return o;
  }();
  return t;
}

const Options<CraigBamptonOptions>& cb_options() {
  static const Options<CraigBamptonOptions> t = [] {
    Options<CraigBamptonOptions> o("CraigBamptonOptions");
    o.add("modes", &CraigBamptonOptions::modes, "fixed-interface modes kept")
        .add("shift", &CraigBamptonOptions::shift, "(rad/s)^2, shift of the shift-invert eigensolver")
        .add("tolerance", &CraigBamptonOptions::tolerance, "relative tolerance of the Ritz values")
        .add("max_iterations", &CraigBamptonOptions::max_iterations, "Lanczos restarts")
        .add("ncv", &CraigBamptonOptions::ncv, "Lanczos basis size; 0 = automatic");
    return o;
  }();
  return t;
}

DofLabel dof_arg(py::handle item, const std::string& source, const std::string& field) {
  // (node, direction) or "node.direction" (e.g. "12.UX", "12.3", "12.z") or "mode k".
  std::string node_text, dir_text;
  if (py::isinstance<py::str>(item)) {
    const std::string s = item.cast<std::string>();
    if (s.rfind("mode ", 0) == 0) return DofLabel::modal(std::stoi(s.substr(5)));
    const auto dot = s.find('.');
    if (dot == std::string::npos) throw InputError(source, field, "\"NODE.DIR\", (node, dir) or \"mode K\"", s);
    node_text = s.substr(0, dot);
    dir_text = s.substr(dot + 1);
  } else {
    auto t = py::reinterpret_borrow<py::sequence>(item);
    if (!py::isinstance<py::sequence>(item) || t.size() != 2) {
      throw InputError(source, field, "\"NODE.DIR\", (node, dir) or \"mode K\"", short_repr(item));
    }
    node_text = std::to_string(integer_arg(t[0], source, field));
    dir_text = std::string(py::str(t[1]));
  }
  auto d = direction_from_string(dir_text);
  char* end = nullptr;
  const long node = std::strtol(node_text.c_str(), &end, 10);
  if (!d || end == node_text.c_str() || *end != '\0' || node < 0) {
    throw InputError(source, field, "\"NODE.DIR\" with DIR in x y z rx ry rz / UX..ROTZ / 1..6", short_repr(item));
  }
  return DofLabel::nodal(node, *d);
}

std::vector<DofLabel> dofs_arg(py::handle obj, const std::string& source) {
  std::vector<DofLabel> out;
  std::size_t i = 0;
  for (auto item : list_arg(obj, source, "dofs", "a list of DOF labels")) {
    out.push_back(dof_arg(item, source, "dofs[" + std::to_string(i++) + "]"));
  }
  return out;
}

py::list dof_names(const std::vector<DofLabel>& dofs) {
  py::list l;
  for (const auto& d : dofs) l.append(d.to_string());
  return l;
}

py::dict coordinates_dict(const std::map<long, Eigen::Vector3d>& c) {
  py::dict d;
  for (const auto& [node, x] : c) d[py::int_(node)] = to_numpy(Eigen::VectorXd(x));
  return d;
}

std::map<long, Eigen::Vector3d> coordinates_arg(py::handle obj, const std::string& source) {
  std::map<long, Eigen::Vector3d> out;
  if (obj.is_none()) return out;
  for (auto item : py::reinterpret_borrow<py::dict>(obj)) {
    const long node = static_cast<long>(integer_arg(item.first, source, "coordinates"));
    auto v = to_vector(item.second, source, "coordinates[" + std::to_string(node) + "]");
    if (v.size() != 3) throw InputError(source, "coordinates[" + std::to_string(node) + "]", "3 values (m)", std::to_string(v.size()));
    out[node] = v;
  }
  return out;
}

// Dense array or scipy.sparse matrix -> Eigen sparse (both triangles).
SparseMatrix sparse_arg(py::handle obj, const std::string& source, const std::string& field) {
  if (py::hasattr(obj, "tocoo")) {
    py::object coo = obj.attr("tocoo")();
    auto rows = py::array_t<long long, py::array::forcecast>::ensure(coo.attr("row"));
    auto cols = py::array_t<long long, py::array::forcecast>::ensure(coo.attr("col"));
    auto vals = vector_arg(coo.attr("data"), source, field);
    auto shape = coo.attr("shape").cast<std::pair<long long, long long>>();
    std::vector<Eigen::Triplet<double, int>> t;
    t.reserve(static_cast<std::size_t>(vals.size()));
    for (py::ssize_t k = 0; k < vals.size(); ++k) {
      t.emplace_back(static_cast<int>(rows.data()[k]), static_cast<int>(cols.data()[k]), vals.data()[k]);
    }
    SparseMatrix s(shape.first, shape.second);
    s.setFromTriplets(t.begin(), t.end());
    return s;
  }
  return to_matrix(obj, source, field).sparseView();
}

}  // namespace

namespace {

// fem.SuperElement (fem/superelement.hpp).
void bind_super_element(py::module_& m) {
  py::class_<SuperElement>(m, "SuperElement", R"(A small dense structural model (fem/superelement.hpp): stiffness K (N/m),
mass M (kg), one label per row ("NODE.UX" .. "NODE.ROTZ" for interface DOF, then "mode k"), node
coordinates (m), the source files and warnings.)")
      .def_property_readonly("K", [](py::object self) { return view(self.cast<const SuperElement&>().K, self); })
      .def_property_readonly("M", [](py::object self) { return view(self.cast<const SuperElement&>().M, self); })
      .def_property_readonly("dofs", [](const SuperElement& s) { return dof_names(s.dofs); })
      .def_property_readonly("coordinates", [](const SuperElement& s) { return coordinates_dict(s.coordinates); })
      .def_property_readonly("nodes", &SuperElement::nodes)
      .def_readonly("source", &SuperElement::source)
      .def_readonly("warnings", &SuperElement::warnings)
      .def_property_readonly("size", &SuperElement::size)
      .def_property_readonly("modal_dofs", &SuperElement::modal_dofs)
      .def_property_readonly("nodal_dofs", &SuperElement::nodal_dofs)
      .def("__repr__", [](const SuperElement& s) {
        return "SuperElement(size=" + std::to_string(s.size()) + ", nodal_dofs=" + std::to_string(s.nodal_dofs()) +
               ", modal_dofs=" + std::to_string(s.modal_dofs()) + ", source=" + s.source + ")";
      });
}

// fem.SparseModel (fem/matrix_io.hpp) and fem.StructuralModel (fem/structural_model.hpp).
void bind_sparse_and_structural_models(py::module_& m) {
  using py::arg;
  py::class_<SparseModel>(m, "SparseModel", "A large sparse FE model (fem/matrix_io.hpp): K (N/m), M (kg), nodal DOF labels.")
      .def(py::init([](py::object K, py::object M, py::object dofs, py::object coordinates) {
             const std::string src = "fem.SparseModel";
             SparseModel s;
             s.K = sparse_arg(K, src, "K");
             s.M = sparse_arg(M, src, "M");
             s.dofs = dofs_arg(dofs, src);
             s.coordinates = coordinates_arg(coordinates, src);
             s.source = "(Python arrays)";
             if (s.K.rows() != s.K.cols() || s.M.rows() != s.K.rows() || s.M.cols() != s.K.cols() ||
                 static_cast<Index>(s.dofs.size()) != s.K.rows()) {
               throw InputError(src, "K, M, dofs", "square K and M of the size of dofs",
                                std::to_string(s.K.rows()) + "x" + std::to_string(s.K.cols()) + ", " +
                                    std::to_string(s.M.rows()) + "x" + std::to_string(s.M.cols()) + ", " +
                                    std::to_string(s.dofs.size()) + " dofs");
             }
             return s;
           }),
           arg("K"), arg("M"), arg("dofs"), arg("coordinates") = py::none(),
           "K, M: dense or scipy.sparse (both triangles); dofs: \"NODE.DIR\" or (node, dir) per row; "
           "coordinates: dict node -> (x, y, z) m.")
      .def_property_readonly("size", &SparseModel::size)
      .def_property_readonly("dofs", [](const SparseModel& s) { return dof_names(s.dofs); })
      .def_readonly("source", &SparseModel::source);

  py::class_<StructuralModel>(m, "StructuralModel", R"(M q'' + C q' + K q = F u, y = T q on the free DOF of a super
element (fem/structural_model.hpp), made by fem.assemble.)")
      .def_property_readonly("K", [](py::object self) { return view(self.cast<const StructuralModel&>().K, self); })
      .def_property_readonly("M", [](py::object self) { return view(self.cast<const StructuralModel&>().M, self); })
      .def_property_readonly("C", [](py::object self) { return view(self.cast<const StructuralModel&>().C, self); })
      .def_property_readonly("F", [](py::object self) { return view(self.cast<const StructuralModel&>().F, self); })
      .def_property_readonly("T", [](py::object self) { return view(self.cast<const StructuralModel&>().T, self); })
      .def_readonly("input_names", &StructuralModel::input_names)
      .def_readonly("output_names", &StructuralModel::output_names)
      .def_property_readonly("size", &StructuralModel::size)
      .def("state_space", [](const StructuralModel& s) { return to_state_space(s); },
           "x = [q; q'] first-order form as an lti.StateSpace.")
      .def(
          "frequency_response",
          [](const StructuralModel& s, py::object omega) {
            auto w = to_vector(omega, "fem.StructuralModel.frequency_response", "omega");
            auto h = without_gil([&] { return frequency_response(s, w); });
            if (w.size() == 0) return py::array(py::array_t<Complex>({py::ssize_t{0}, py::ssize_t{s.T.rows()}, py::ssize_t{s.F.cols()}}));
            return response_array(h, false);
          },
          arg("omega"), "T (K - w^2 M + j w C)^-1 F at every omega (rad/s): (len(omega), outputs, inputs).");
}

// read_super_element and read_calculix_model.
void bind_readers(py::module_& m) {
  using py::arg;
  m.def(
      "read_super_element",
      [](const std::string& k_file, const std::string& m_file, const std::string& nodes_file,
         const std::string& coordinates_file, const std::string& format, const py::kwargs& kw) {
        const std::string src = "fem.read_super_element";
        auto o = import_options().from_kwargs(kwargs_dict(kw), src);
        SuperElementFormat f;
        if (format == "auto") {
          f = detect_format(k_file);
        } else {
          auto parsed = super_element_format_from_string(format);
          if (!parsed) throw InputError(src, "format", "auto, ansys, calculix or matrix-market", format);
          f = *parsed;
        }
        return without_gil([&] { return read_super_element(f, k_file, m_file, nodes_file, coordinates_file, o); });
      },
      arg("k_file"), arg("m_file"), arg("nodes_file"), arg("coordinates_file") = "", arg("format") = "auto",
      ("Reads a super element: Ansys CMS text (K, M, master DOF list, node list), CalculiX MATRIXSTORAGE\n"
       "(.sti, .mas, .dof, optional .inp) or Matrix Market with a DOF list. format: auto, ansys,\n"
       "calculix, matrix-market.\n\nKeywords (ImportOptions):\n" + import_options().doc())
          .c_str());
  m.def(
      "read_calculix_model",
      [](const std::string& sti, const std::string& mas, const std::string& dof, const std::string& inp) {
        return without_gil([&] { return read_calculix_model(sti, mas, dof, inp); });
      },
      arg("sti_file"), arg("mas_file"), arg("dof_file"), arg("nodes_inp") = "",
      "A large model from CalculiX MATRIXSTORAGE dumps, as a fem.SparseModel (for craig_bampton).");
}

// modes, assemble and check_rigid_body_modes.
void bind_analyses(py::module_& m) {
  using py::arg;
  m.def(
      "modes",
      [](py::object K, py::object M) {
        return fem::modes(to_matrix(K, "fem.modes", "K"), to_matrix(M, "fem.modes", "M"));
      },
      arg("K"), arg("M"),
      "Undamped modes K phi = w^2 M phi: a fem.Modes(frequencies_Hz (signed, ascending), shapes (mass-normalized columns)).");
  m.def(
      "assemble",
      [](const SuperElement& se, const std::vector<long>& fixed_nodes, const std::vector<std::string>& masses,
         const std::vector<std::string>& forces, const std::vector<std::string>& outputs, const std::string& damping) {
        ModelOptions o;
        o.fixed_nodes = fixed_nodes;
        for (std::size_t i = 0; i < masses.size(); ++i) o.masses.push_back(PointMass::parse(masses[i], "masses[" + std::to_string(i) + "]"));
        for (std::size_t i = 0; i < forces.size(); ++i) o.forces.push_back(ForcePair::parse(forces[i], "forces[" + std::to_string(i) + "]"));
        for (std::size_t i = 0; i < outputs.size(); ++i) {
          o.outputs.push_back(DisplacementOutput::parse(outputs[i], "outputs[" + std::to_string(i) + "]"));
        }
        o.damping = fem::Damping::parse(damping, "damping");
        return assemble(se, o);
      },
      arg("se"), arg("fixed_nodes") = std::vector<long>{}, arg("masses") = std::vector<std::string>{},
      arg("forces") = std::vector<std::string>{}, arg("outputs") = std::vector<std::string>{}, arg("damping") = "none",
      "Boundary conditions, point masses (\"NODE:KG\"), force pairs (\"A:B:DIR\" or \"B:DIR\", inputs), displacement\n"
      "outputs (\"NODE:DIR\" or \"A:B:DIR\") and damping (\"none\", \"modal:ZETA\", \"rayleigh:A:B\") applied to a\n"
      "super element: a fem.StructuralModel.");
  m.def(
      "check_rigid_body_modes",
      [](const SuperElement& se, double threshold) {
        return check_rigid_body_modes(se, threshold);
      },
      arg("se"), arg("relative_threshold") = 1e-3, "Are the six free-free rigid-body modes at ~0 Hz? A fem.RigidBodyCheck.");
}

// craig_bampton (fem/craig_bampton.hpp).
void bind_reduction(py::module_& m) {
  using py::arg;
  m.def(
      "craig_bampton",
      [](const SparseModel& model, py::object interface, const py::kwargs& kw) {
        const std::string src = "fem.craig_bampton";
        auto o = cb_options().from_kwargs(kwargs_dict(kw), src);
        std::vector<InterfacePoint> points;
        std::size_t i = 0;
        for (auto item : list_arg(interface, src, "interface", "a list of nodes or \"REF:ROT\" strings")) {
          const std::string field = "interface[" + std::to_string(i++) + "]";
          const std::string text = py::isinstance<py::str>(item) ? std::string(py::str(item))
                                                                 : std::to_string(integer_arg(item, src, field));
          points.push_back(InterfacePoint::parse(text, field));
        }
        return without_gil([&] { return craig_bampton(model, points, o); });
      },
      arg("model"), arg("interface"),
      ("Craig-Bampton reduction of a fem.SparseModel to a super element: interface points are nodes\n"
       "(int or \"NODE\") or \"REF:ROT\" rigid bodies. A fem.CraigBamptonResult(reduced (SuperElement), fixed_interface_Hz, ...).\n\n"
       "Keywords (CraigBamptonOptions):\n" + cb_options().doc())
          .c_str());
}

}  // namespace

void bind_fem(py::module_& m) {
  bind_super_element(m);
  // The declared results (fem/*.hpp's describe); CraigBamptonResult.reduced is a fem.SuperElement.
  bind_described<Modes>(m);
  bind_described<RigidBodyCheck>(m);
  bind_described<CraigBamptonResult>(m);
  m.def("declarations", [] { return declarations_of<Modes, RigidBodyCheck, CraigBamptonResult>(); },
        "{declared struct: (its Python class, [field names])} for every declared result fem returns (fem/*.hpp).");
  bind_sparse_and_structural_models(m);
  bind_readers(m);
  bind_analyses(m);
  bind_reduction(m);
}

}  // namespace piezobench::python
