// piezobench.lti: include/piezobench/lti/*.hpp
#include "piezobench/lti.hpp"

#include "common.hpp"
#include "described.hpp"
#include "piezobench/core/format.hpp"

namespace piezobench::python {
namespace {

using namespace piezobench::lti;

}  // namespace

const Options<RootLocusOptions>& root_locus_options() {
  static const Options<RootLocusOptions> t = [] {
    Options<RootLocusOptions> o("RootLocusOptions");
    o.add("gain_min", &RootLocusOptions::gain_min, "first gain of the automatic grid (>= 0)")
        .add("gain_max", &RootLocusOptions::gain_max,
             "last gain; 0 = automatic (until every branch settles on a zero or leaves for infinity)")
        .add("max_relative_step", &RootLocusOptions::max_relative_step,
             "largest pole move between consecutive gains, relative to the pole's scale")
        .add("settle_fraction", &RootLocusOptions::settle_fraction, "a branch has settled within this fraction")
        .add("max_points", &RootLocusOptions::max_points, "largest number of gains");
    return o;
  }();
  return t;
}

namespace {

const Options<RootLocusOptions>& rlocus_options() { return root_locus_options(); }

const Options<DiscretizeOptions>& discretize_options() {
  static const Options<DiscretizeOptions> t = [] {
    Options<DiscretizeOptions> o("DiscretizeOptions");
    o.add_enum("method", &DiscretizeOptions::method, &lti::to_string, &discretization_method_from_string,
               "\"zoh\" or \"tustin\"")
        .add("prewarp_frequency", &DiscretizeOptions::prewarp_frequency,
             "rad/s, Tustin only: where the discrete response matches exactly; 0 = none");
    return o;
  }();
  return t;
}

}  // namespace

py::array response_array(const FrequencyResponse& r, bool squeeze_siso) {
  // omega.size() x outputs x inputs, complex128; SISO: 1-D.
  const Index n = r.omega.size();
  if (n == 0) return to_numpy(Eigen::VectorXcd());
  const Index p = r.H[0].rows(), q = r.H[0].cols();
  if (squeeze_siso && p == 1 && q == 1) return to_numpy(r.channel(0, 0));
  py::array_t<Complex> out({n, p, q});
  auto a = out.mutable_unchecked<3>();
  for (Index k = 0; k < n; ++k)
    for (Index i = 0; i < p; ++i)
      for (Index j = 0; j < q; ++j) a(k, i, j) = r.H[k](i, j);
  return out;
}

namespace {

std::string ss_repr(const StateSpace& s) {
  return "StateSpace(states=" + std::to_string(s.states()) + ", inputs=" + std::to_string(s.inputs()) +
         ", outputs=" + std::to_string(s.outputs()) + ", sample_time=" + format_number(s.sample_time, 10) +
         (s.has_delay() ? ", delayed" : "") + ")";
}

}  // namespace

StateSpace state_space_arg(py::handle obj, const std::string& source, const std::string& field) {
  if (py::isinstance<StateSpace>(obj)) return obj.cast<StateSpace>();
  if (py::isinstance<TransferFunction>(obj)) return to_state_space(obj.cast<TransferFunction>());
  if (py::isinstance<Zpk>(obj)) return to_state_space(obj.cast<Zpk>());
  throw InputError(source, field, "an lti.StateSpace, lti.TransferFunction or lti.Zpk", short_repr(obj));
}

namespace {

// lti.StateSpace (lti/state_space.hpp).
void bind_state_space(py::module_& m) {
  using py::arg;
  py::class_<StateSpace>(m, "StateSpace", R"(Linear time-invariant system in state-space form (lti/state_space.hpp).

continuous (sample_time == 0): dx/dt = A x + B u(t - input_delay),  y = C x + D u
discrete   (sample_time  > 0): x[k+1] = A x[k] + B u[k],            y[k] = C x[k] + D u[k]
Delays (s) are exact in frequency responses; lti.pade() turns them into states. SI units;
poles in rad/s (continuous) or the z-plane (discrete).)")
      .def(py::init([](py::object a, py::object b, py::object c, py::object d, double ts, py::object in_delay,
                       py::object out_delay) {
             const std::string src = "lti.StateSpace";
             StateSpace s(to_matrix(a, src, "A"), to_matrix(b, src, "B", true), to_matrix(c, src, "C"),
                          d.is_none() ? Eigen::MatrixXd() : to_matrix(d, src, "D"), ts);
             if (!in_delay.is_none()) s.input_delay = to_vector(in_delay, src, "input_delay");
             if (!out_delay.is_none()) s.output_delay = to_vector(out_delay, src, "output_delay");
             s.validate(src);
             return s;
           }),
           arg("A"), arg("B"), arg("C"), arg("D") = py::none(), arg("sample_time") = 0.0,
           arg("input_delay") = py::none(), arg("output_delay") = py::none(),
           "A (states x states), B (states x inputs), C (outputs x states), D (outputs x inputs; None = 0); "
           "sample_time s (0 = continuous); input_delay / output_delay s per input / output")
      .def_property_readonly("A", [](const StateSpace& s) { return to_numpy(s.A); })
      .def_property_readonly("B", [](const StateSpace& s) { return to_numpy(s.B); })
      .def_property_readonly("C", [](const StateSpace& s) { return to_numpy(s.C); })
      .def_property_readonly("D", [](const StateSpace& s) { return to_numpy(s.D); })
      .def_readonly("sample_time", &StateSpace::sample_time, "s; 0 = continuous")
      .def_property_readonly("input_delay", [](const StateSpace& s) { return to_numpy(s.input_delay); }, "s")
      .def_property_readonly("output_delay", [](const StateSpace& s) { return to_numpy(s.output_delay); }, "s")
      .def_property_readonly("states", &StateSpace::states)
      .def_property_readonly("inputs", &StateSpace::inputs)
      .def_property_readonly("outputs", &StateSpace::outputs)
      .def_property_readonly("is_discrete", &StateSpace::is_discrete)
      .def("__repr__", &ss_repr);
}

// lti.TransferFunction and lti.Zpk (lti/transfer_function.hpp).
void bind_siso_forms(py::module_& m) {
  using py::arg;
  py::class_<TransferFunction>(m, "TransferFunction", R"(SISO transfer function num(s)/den(s) exp(-s delay)
(lti/transfer_function.hpp). Coefficients in descending powers of s (z when discrete), as MATLAB's tf.)")
      .def(py::init([](py::object num, py::object den, double ts, double delay) {
             return TransferFunction(to_vector(num, "lti.TransferFunction", "num"),
                                     to_vector(den, "lti.TransferFunction", "den"), ts, delay);
           }),
           arg("num"), arg("den"), arg("sample_time") = 0.0, arg("delay") = 0.0)
      .def_property_readonly("num", [](const TransferFunction& t) { return to_numpy(t.num); })
      .def_property_readonly("den", [](const TransferFunction& t) { return to_numpy(t.den); })
      .def_readonly("sample_time", &TransferFunction::sample_time, "s; 0 = continuous")
      .def_readonly("delay", &TransferFunction::delay, "s")
      .def("__repr__", [](const TransferFunction& t) {
        return "TransferFunction(order=" + std::to_string(t.order()) +
               ", sample_time=" + format_number(t.sample_time, 10) + ", delay=" + format_number(t.delay, 10) + ")";
      });

  py::class_<Zpk>(m, "Zpk", R"(SISO zeros, poles and gain: gain prod(s - zeros) / prod(s - poles) exp(-s delay)
(lti/transfer_function.hpp). Complex values in conjugate pairs; rad/s (continuous) or z-plane.)")
      .def(py::init([](py::object z, py::object p, double k, double ts, double delay) {
             return Zpk(to_complex_vector(z, "lti.Zpk", "zeros"), to_complex_vector(p, "lti.Zpk", "poles"), k, ts, delay);
           }),
           arg("zeros"), arg("poles"), arg("gain"), arg("sample_time") = 0.0, arg("delay") = 0.0)
      .def_property_readonly("zeros", [](const Zpk& z) { return to_numpy(z.zeros); })
      .def_property_readonly("poles", [](const Zpk& z) { return to_numpy(z.poles); })
      .def_readonly("gain", &Zpk::gain)
      .def_readonly("sample_time", &Zpk::sample_time, "s; 0 = continuous")
      .def_readonly("delay", &Zpk::delay, "s")
      .def("__repr__", [](const Zpk& z) {
        return "Zpk(zeros=" + std::to_string(z.zeros.size()) + ", poles=" + std::to_string(z.poles.size()) +
               ", gain=" + format_number(z.gain) + ")";
      });
}

// ss, tf and zpk: one form from another.
void bind_conversions(py::module_& m) {
  using py::arg;
  m.def("ss", [](py::object sys) { return state_space_arg(sys, "lti.ss", "sys"); }, arg("sys"),
        "The state space of a StateSpace, TransferFunction or Zpk (cascade of real sections from the zpk form).");
  m.def(
      "tf",
      [](py::object sys, Index output, Index input) -> TransferFunction {
        if (py::isinstance<Zpk>(sys)) return to_transfer_function(sys.cast<Zpk>());
        if (py::isinstance<TransferFunction>(sys)) return sys.cast<TransferFunction>();
        return to_transfer_function(state_space_arg(sys, "lti.tf", "sys"), output, input);
      },
      arg("sys"), arg("output") = 0, arg("input") = 0, "Transfer function of one channel (output, input) of sys.");
  m.def(
      "zpk",
      [](py::object sys, Index output, Index input) -> Zpk {
        if (py::isinstance<TransferFunction>(sys)) return to_zpk(sys.cast<TransferFunction>());
        if (py::isinstance<Zpk>(sys)) return sys.cast<Zpk>();
        return to_zpk(state_space_arg(sys, "lti.zpk", "sys"), output, input);
      },
      arg("sys"), arg("output") = 0, arg("input") = 0,
      "Zeros, poles and gain of one channel (output, input): poles of A, transmission zeros, gain from H.");
}

// freqresp, logspace, poles, zeros, dc_gain and damp.
void bind_frequency_analysis(py::module_& m) {
  using py::arg;
  m.def(
      "freqresp",
      [](py::object sys, py::object omega, int threads) -> py::array {
        auto w = to_vector(omega, "lti.freqresp", "omega");
        if (py::isinstance<Zpk>(sys)) {
          auto z = sys.cast<Zpk>();
          return to_numpy(without_gil([&] { return lti::freqresp(z, w); }));
        }
        if (py::isinstance<TransferFunction>(sys)) {
          auto t = sys.cast<TransferFunction>();
          return to_numpy(without_gil([&] { return lti::freqresp(t, w); }));
        }
        auto s = state_space_arg(sys, "lti.freqresp", "sys");
        auto r = without_gil([&] { return FrequencyResponseEvaluator(s).response(w, threads); });
        return response_array(r, true);
      },
      arg("sys"), arg("omega"), arg("threads") = 1,
      R"(H(j omega) at every omega (rad/s), delays exact. SISO: a 1-D complex array; MIMO state space:
shape (len(omega), outputs, inputs). Discrete systems use z = exp(j omega Ts). State spaces go
through a Hessenberg reduction (O(n^2) per frequency), zpk forms as products of factors.)");
  m.def("logspace", [](double lo, double hi, Index n) { return to_numpy(lti::logspace(lo, hi, n)); }, arg("lo_exponent"), arg("hi_exponent"), arg("n"),
        "n points from 10**lo to 10**hi, logarithmically spaced (as MATLAB's logspace).");
  m.def("poles", [](py::object sys) { return to_numpy(lti::poles(state_space_arg(sys, "lti.poles", "sys"))); },
        arg("sys"), "Eigenvalues of A (rad/s or z-plane), by increasing magnitude, conjugates adjacent.");
  m.def("zeros", [](py::object sys) { return to_numpy(lti::zeros(state_space_arg(sys, "lti.zeros", "sys"))); },
        arg("sys"), "Transmission zeros (system pencil, Emami-Naeini & Van Dooren), sorted as poles().");
  m.def("dc_gain", [](py::object sys) { return to_numpy(lti::dc_gain(state_space_arg(sys, "lti.dc_gain", "sys"))); },
        arg("sys"), "H(0) (continuous) or H(1) (discrete), outputs x inputs; +-inf for an uncancelled integrator.");
  m.def(
      "damp",
      [](py::object sys) {
        return lti::damp_columns(state_space_arg(sys, "lti.damp", "sys"));
      },
      arg("sys"), "Poles with natural frequency (rad/s) and damping ratio (as MATLAB's damp): an lti.Damping.");
}

// c2d, lsim, step, impulse, expm and pade.
void bind_time_domain(py::module_& m) {
  using py::arg;
  m.def(
      "c2d",
      [](py::object sys, double ts, const py::kwargs& kw) -> py::object {
        auto o = discretize_options().from_kwargs(kwargs_dict(kw), "lti.c2d");
        if (py::isinstance<TransferFunction>(sys)) return py::cast(lti::c2d(sys.cast<TransferFunction>(), ts, o));
        return py::cast(lti::c2d(state_space_arg(sys, "lti.c2d", "sys"), ts, o));
      },
      arg("sys"), arg("sample_time"),
      ("Continuous -> discrete with sample time Ts (s): ZOH (exact for held inputs) or Tustin (bilinear,\n"
       "optionally pre-warped). A TransferFunction gives a TransferFunction, else a StateSpace.\n\nKeywords:\n" +
       discretize_options().doc())
          .c_str());
  m.def(
      "lsim",
      [](py::object sys_arg, py::object u, py::object x0) {
        auto sys = state_space_arg(sys_arg, "lti.lsim", "sys");
        auto um = to_matrix(u, "lti.lsim", "u", true);
        Eigen::VectorXd x = x0.is_none() ? Eigen::VectorXd() : to_vector(x0, "lti.lsim", "x0");
        return without_gil([&] { return lti::lsim(sys, um, x); });
      },
      arg("sys"), arg("u"), arg("x0") = py::none(),
      "Response of a discrete system to u (samples x inputs; 1-D for one input) from x0 (None = 0).\n"
      "Returns an lti.TimeResponse: t (s), y (samples x outputs), x (samples x states).");
  m.def(
      "step",
      [](py::object sys, double ts, Index samples, Index input) {
        return lti::step(state_space_arg(sys, "lti.step", "sys"), ts, samples, input);
      },
      arg("sys"), arg("sample_time"), arg("samples"), arg("input") = 0,
      "Unit-step response (continuous systems discretized by ZOH at sample_time): lti.TimeResponse(t, y, x).");
  m.def(
      "impulse",
      [](py::object sys, double ts, Index samples, Index input) {
        return lti::impulse(state_space_arg(sys, "lti.impulse", "sys"), ts, samples, input);
      },
      arg("sys"), arg("sample_time"), arg("samples"), arg("input") = 0,
      "Unit-impulse response (area-1 pulse over the first sample for continuous systems): lti.TimeResponse(t, y, x).");
  m.def("expm", [](py::object a) { return to_numpy(lti::expm(to_matrix(a, "lti.expm", "a"))); }, arg("a"),
        "Matrix exponential (scaling and squaring, [13/13] Pade; Higham 2005).");
  m.def("pade", [](double delay, int order) { return lti::pade(delay, order); }, arg("delay"), arg("order"),
        "[order/order] Pade approximant of exp(-s delay) (delay in s), as MATLAB's pade(T, N).");
}

// series, parallel and feedback.
void bind_interconnections(py::module_& m) {
  using py::arg;
  m.def("series", [](py::object a, py::object b) {
    return lti::series(state_space_arg(a, "lti.series", "first"), state_space_arg(b, "lti.series", "second"));
  }, arg("first"), arg("second"), "y = second(first(u)).");
  m.def("parallel", [](py::object a, py::object b) {
    return lti::parallel(state_space_arg(a, "lti.parallel", "a"), state_space_arg(b, "lti.parallel", "b"));
  }, arg("a"), arg("b"), "y = a(u) + b(u).");
  m.def(
      "feedback",
      [](py::object f, py::object b, int sign) {
        if (sign != 1 && sign != -1) throw InputError("lti.feedback", "sign", "-1 or +1", std::to_string(sign));
        return lti::feedback(state_space_arg(f, "lti.feedback", "forward"), state_space_arg(b, "lti.feedback", "back"),
                             sign < 0 ? FeedbackSign::kNegative : FeedbackSign::kPositive);
      },
      arg("forward"), arg("back"), arg("sign") = -1,
      "Closed loop r -> y of y = forward(u), u = r + sign back(y) (MATLAB feedback with sign -1).");
}

// closed_loop_poles, rlocus and max_damping_on_branch.
void bind_root_locus(py::module_& m) {
  using py::arg;
  m.def(
      "closed_loop_poles",
      [](py::object sys, double gain) {
        return to_numpy(lti::closed_loop_poles(state_space_arg(sys, "lti.closed_loop_poles", "open_loop"), gain));
      },
      arg("open_loop"), arg("gain"), "Poles of 1 + k L(s) = 0 (negative feedback u = -k y, MATLAB's rlocus).");
  m.def(
      "rlocus",
      [](py::object sys, py::object gains, const py::kwargs& kw) {
        auto s = state_space_arg(sys, "lti.rlocus", "open_loop");
        auto o = rlocus_options().from_kwargs(kwargs_dict(kw), "lti.rlocus");
        if (gains.is_none()) return without_gil([&] { return lti::rlocus_auto(s, o); });
        auto g = vector_arg(gains, "lti.rlocus", "gains");
        std::vector<double> gv(g.data(), g.data() + g.size());
        return without_gil([&] { return lti::rlocus(s, gv); });
      },
      arg("open_loop"), arg("gains") = py::none(),
      ("Root locus of the SISO loop L under u = -k y: an lti.RootLocus(gains, poles) with poles[i] the closed-loop\n"
       "poles at gains[i] (branches kept in a consistent column order). gains None = automatic grid.\n\n"
       "Keywords (automatic grid):\n" + rlocus_options().doc())
          .c_str());
  m.def(
      "max_damping_on_branch",
      [](py::object sys, Complex start, const py::kwargs& kw) {
        auto s = state_space_arg(sys, "lti.max_damping_on_branch", "open_loop");
        auto o = rlocus_options().from_kwargs(kwargs_dict(kw), "lti.max_damping_on_branch");
        return without_gil([&] { return lti::max_damping_on_branch(s, start, o); });
      },
      arg("open_loop"), arg("start_pole"),
      ("The gain of maximum damping on the branch starting at the open-loop pole nearest start_pole\n"
       "(golden section to 1e-6): an lti.BranchOptimum(gain, damping, pole).\n\nKeywords:\n" + rlocus_options().doc())
          .c_str());
}

}  // namespace

void bind_lti(py::module_& m) {
  // The declared results (lti/*.hpp's describe), bound before the functions that return them.
  bind_described<TimeResponse>(m);
  bind_described<RootLocus>(m);
  bind_described<Damping>(m);
  bind_described<BranchOptimum>(m);
  bind_state_space(m);
  bind_siso_forms(m);
  bind_conversions(m);
  bind_frequency_analysis(m);
  bind_time_domain(m);
  bind_interconnections(m);
  bind_root_locus(m);
  m.def("declarations", [] { return declarations_of<TimeResponse, RootLocus, Damping, BranchOptimum>(); },
        "{declared struct: (its Python class, [field names])} for every declared result lti returns (lti/*.hpp).");
}

}  // namespace piezobench::python
