// piezobench.control: include/piezobench/control/{iff,discrete_iff}.hpp
#include "common.hpp"
#include "described.hpp"
#include "piezobench/control/discrete_iff.hpp"
#include "piezobench/control/iff.hpp"
#include "piezobench/lti/conversions.hpp"

namespace piezobench::python {
namespace {

using namespace piezobench::control;
using lti::Index;

const Options<IffPlantParams>& plant_options() {
  static const Options<IffPlantParams> t = [] {
    Options<IffPlantParams> o("IffPlantParams");
    o.add("g0", &IffPlantParams::g0, "V/V, gain")
        .add("wz", &IffPlantParams::wz, "rad/s, anti-resonance")
        .add("xz", &IffPlantParams::xz, "damping ratio of the zero (< 0: non-minimum phase)")
        .add("wp", &IffPlantParams::wp, "rad/s, resonance")
        .add("xp", &IffPlantParams::xp, "damping ratio of the pole")
        .add("w_hpf", &IffPlantParams::w_hpf, "rad/s, high-pass corner of the resistor across the sensor stack")
        .add("delay", &IffPlantParams::delay, "s");
    return o;
  }();
  return t;
}

const Options<IffControllerParams>& controller_options() {
  static const Options<IffControllerParams> t = [] {
    Options<IffControllerParams> o("IffControllerParams");
    o.add("gain", &IffControllerParams::gain, "1/s^2 scaling of the report's controller (eq. 2.4)")
        .add("w_hpf", &IffControllerParams::w_hpf, "rad/s, high-pass that limits the low-frequency gain")
        .add("w_lpf", &IffControllerParams::w_lpf, "rad/s, integral action above it")
        .add("w_robust", &IffControllerParams::w_robust, "rad/s, roll-off for robustness");
    return o;
  }();
  return t;
}

const Options<IffLoopOptions>& loop_options() {
  static const Options<IffLoopOptions> t = [] {
    Options<IffLoopOptions> o("IffLoopOptions");
    o.add("pade_order", &IffLoopOptions::pade_order, "Pade order for delays of the plant or controller")
        .add("resonance", &IffLoopOptions::resonance,
             "rad/s of the resonance whose branch is optimized; None = the least damped complex pole")
        .add_nested("locus", &IffLoopOptions::locus, root_locus_options(), "root-locus grid (lti.rlocus keywords)");
    return o;
  }();
  return t;
}

const Options<DiscreteIffOptions>& discrete_options() {
  static const Options<DiscreteIffOptions> t = [] {
    Options<DiscreteIffOptions> o("DiscreteIffOptions");
    o.add("sample_rate", &DiscreteIffOptions::sample_rate, "Hz, loop rate")
        .add("prewarp", &DiscreteIffOptions::prewarp, "rad/s, Tustin pre-warping frequency; 0 = none")
        .add("antiwindup_gain", &DiscreteIffOptions::antiwindup_gain, "in [0, 1]; 0 = off");
    return o;
  }();
  return t;
}

}  // namespace

void bind_control(py::module_& m) {
  using py::arg;
  bind_described<IffRootLocus>(m);  // its lti.RootLocus and lti.BranchOptimum are lti's classes
  // The controller a result holds (campaign.IffStudy.controller), from its declaration (control/iff.hpp).
  bind_described<IffControllerParams>(m);
  m.def("declarations", [] { return declarations_of<IffRootLocus, IffControllerParams>(); },
        "{declared struct: (its Python class, [field names])} for every declared result control returns (control/iff.hpp).");

  m.def(
      "iff_plant",
      [](const py::kwargs& kw) {
        auto p = plant_options().from_kwargs(kwargs_dict(kw), "control.iff_plant");
        return iff_plant(p);
      },
      ("G(s) = g0 (1 + 2 xz s/wz + s^2/wz^2) / (1 + 2 xp s/wp + s^2/wp^2) s/(w_hpf + s) exp(-s delay), u (V) -> Vs (V)\n"
       "(report eq. 2.3); defaults: the report's manual fit. Returns an lti.TransferFunction.\n\nKeywords:\n" +
       plant_options().doc())
          .c_str());
  m.def(
      "iff_controller",
      [](const py::kwargs& kw) {
        auto p = controller_options().from_kwargs(kwargs_dict(kw), "control.iff_controller");
        return iff_controller(p);
      },
      ("K0(s) = gain s/(s + w_hpf) 1/(s + w_lpf) 1/(s + w_robust) (report eq. 2.4 at g = 1). Returns an lti.Zpk.\n\n"
       "Keywords:\n" + controller_options().doc())
          .c_str());
  m.def(
      "iff_open_loop",
      [](py::object plant, py::object controller, const py::kwargs& kw) {
        auto o = loop_options().from_kwargs(kwargs_dict(kw), "control.iff_open_loop");
        return iff_open_loop(state_space_arg(plant, "control.iff_open_loop", "plant"),
                             state_space_arg(controller, "control.iff_open_loop", "controller"), o);
      },
      arg("plant"), arg("controller"),
      ("L = -K0 G as a SISO state space (delays as Pade approximants).\n\nKeywords:\n" + loop_options().doc()).c_str());
  m.def(
      "iff_root_locus",
      [](py::object plant, py::object controller, py::object gains, const py::kwargs& kw) {
        const std::string src = "control.iff_root_locus";
        auto o = loop_options().from_kwargs(kwargs_dict(kw), src);
        auto g = state_space_arg(plant, src, "plant");
        auto k = state_space_arg(controller, src, "controller");
        std::vector<double> gv;
        if (!gains.is_none()) {
          auto a = vector_arg(gains, src, "gains");
          gv.assign(a.data(), a.data() + a.size());
        }
        return without_gil([&] { return iff_root_locus(g, k, gv, o); });
      },
      arg("plant"), arg("controller"), arg("gains") = py::none(),
      ("Root locus of the IFF loop 1 - g K0 G = 0 (report Figure 2.9) at `gains` (None = automatic) and the\n"
       "gain of maximum damping on the resonance branch: a control.IffRootLocus(locus (an lti.RootLocus),\n"
       "resonance_pole, optimum (an lti.BranchOptimum), resonance_branch).\n\nKeywords:\n" + loop_options().doc())
          .c_str());

  py::class_<DiscreteIff>(m, "DiscreteIff", R"(The report's IFF controller as it runs on the real-time target
(control/discrete_iff.hpp): Tustin with pre-warping, second-order sections, bumpless gain changes,
anti-windup. y[k] = g K0(z) Vs[k]; a non-finite input resets the states and gives 0.)")
      .def(py::init([](double gain, py::object controller, const py::kwargs& kw) {
             const std::string src = "control.DiscreteIff";
             auto o = discrete_options().from_kwargs(kwargs_dict(kw), src);
             IffControllerParams p;
             if (!controller.is_none()) {
               if (!py::isinstance<py::dict>(controller)) throw InputError(src, "controller", "a dict of iff_controller keywords", short_repr(controller));
               p = controller_options().from_kwargs(py::reinterpret_borrow<py::dict>(controller), src);
             }
             return DiscreteIff(p, o, gain);
           }),
           arg("gain") = 0.0, arg("controller") = py::none(),
           ("gain: g; controller: dict of iff_controller keywords (None = the report's).\n\nKeywords:\n" +
            discrete_options().doc())
               .c_str())
      .def("step", &DiscreteIff::step, arg("vs"), "One sample: returns g K0 Vs (V).")
      .def(
          "run",
          [](DiscreteIff& c, py::object vs) {
            auto a = vector_arg(vs, "control.DiscreteIff.run", "vs", false);
            Eigen::VectorXd y(a.size());
            {
              py::gil_scoped_release release;
              for (Index k = 0; k < y.size(); ++k) y(k) = c.step(a.data()[k]);
            }
            return to_numpy(std::move(y));
          },
          arg("vs"), "step() over every sample of vs (1-D, V), in order; returns the outputs.")
      .def("applied", &DiscreteIff::applied, arg("output"), "Tell the controller what was really applied (anti-windup).")
      .def("set_gain", &DiscreteIff::set_gain, arg("gain"), "New gain from the next sample on (False if not finite).")
      .def_property_readonly("gain", &DiscreteIff::gain)
      .def("reset", &DiscreteIff::reset, "Zero states; the gain is kept.")
      .def_property_readonly("nonfinite_inputs", &DiscreteIff::nonfinite_inputs)
      .def("model", &DiscreteIff::model, "The discrete controller at gain 1 as an lti.StateSpace (input Vs, output y).");
}

}  // namespace piezobench::python
