#include "piezobench/dsp/frf.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <set>
#include <vector>

#include "piezobench/core/error.hpp"
#include "piezobench/core/format.hpp"
#include "piezobench/core/units.hpp"

namespace piezobench::dsp {

using Eigen::Index;

Index Frf::output_index(const std::string& name) const {
  std::string known;
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (outputs[i] == name) return static_cast<Index>(i);
    known += (known.empty() ? "" : ", ") + outputs[i];
  }
  throw InputError(provenance.source, "output", "one of " + (known.empty() ? std::string("(no outputs)") : known),
                   "\"" + name + "\"");
}

void Frf::validate(const std::string& source) const {
  const std::string src = source.empty() ? provenance.source : source;
  const Index n = freq_Hz.size();
  if (n < 1) throw InputError(src, "freq_Hz", "at least one frequency", "none");
  if (std::isfinite(freq_Hz(0)) && freq_Hz(0) < 0.0) {
    throw InputError(src, "freq_Hz", "frequencies >= 0 Hz (one-sided FRF)",
                     format_number(freq_Hz(0), 10) + " Hz at index 0");
  }
  for (Index k = 0; k < n; ++k) {
    if (!std::isfinite(freq_Hz(k))) {
      throw InputError(src, "freq_Hz", "finite frequencies", "non-finite value at index " + std::to_string(k));
    }
    if (k > 0 && !(freq_Hz(k) > freq_Hz(k - 1))) {
      throw InputError(src, "freq_Hz", "strictly increasing frequencies",
                       format_number(freq_Hz(k - 1), 10) + " then " + format_number(freq_Hz(k), 10) + " at index " +
                           std::to_string(k));
    }
  }
  if (outputs.empty()) throw InputError(src, "outputs", "at least one output", "none");
  if (H.size() != outputs.size()) {
    throw InputError(src, "H", std::to_string(outputs.size()) + " responses (one per output)", std::to_string(H.size()));
  }
  std::set<std::string> names;
  for (const auto& name : outputs) {
    if (!names.insert(name).second) throw InputError(src, "outputs", "distinct output names", "\"" + name + "\" twice");
  }
  if (!coherence.empty() && coherence.size() != outputs.size()) {
    throw InputError(src, "coherence", "none or " + std::to_string(outputs.size()) + " (one per output)",
                     std::to_string(coherence.size()));
  }
  if (!std_H.empty() && std_H.size() != outputs.size()) {
    throw InputError(src, "std_H", "none or " + std::to_string(outputs.size()) + " (one per output)", std::to_string(std_H.size()));
  }
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    if (H[i].size() != n) {
      throw InputError(src, outputs[i], std::to_string(n) + " values (one per frequency)", std::to_string(H[i].size()));
    }
    for (Index k = 0; k < n; ++k) {
      if (!std::isfinite(H[i](k).real()) || !std::isfinite(H[i](k).imag())) {
        throw InputError(
            src, outputs[i], "finite response values",
            "non-finite value at " + format_number(freq_Hz(k), 10) + " Hz (index " + std::to_string(k) + ")");
      }
    }
    if (!coherence.empty()) {
      if (coherence[i].size() != n) {
        throw InputError(src, outputs[i] + " coherence", std::to_string(n) + " values (one per frequency)",
                         std::to_string(coherence[i].size()));
      }
      for (Index k = 0; k < n; ++k) {
        if (!std::isfinite(coherence[i](k))) {
          throw InputError(
              src, outputs[i] + " coherence", "finite values",
              "non-finite value at " + format_number(freq_Hz(k), 10) + " Hz (index " + std::to_string(k) + ")");
        }
        // Magnitude-squared coherence lies in [0, 1]; the tolerance admits round-off only.
        if (coherence[i](k) < 0.0 || coherence[i](k) > 1.0 + 1e-9) {
          throw InputError(src, outputs[i] + " coherence", "values in [0, 1]",
                           format_number(coherence[i](k), 10) + " at " + format_number(freq_Hz(k), 10) + " Hz (index " +
                               std::to_string(k) + ")");
        }
      }
    }
    if (!std_H.empty()) {
      if (std_H[i].size() != n) {
        throw InputError(src, outputs[i] + " std", std::to_string(n) + " values (one per frequency)", std::to_string(std_H[i].size()));
      }
      for (Index k = 0; k < n; ++k) {
        if (!std::isfinite(std_H[i](k)) || std_H[i](k) < 0.0) {
          throw InputError(src, outputs[i] + " std", "finite values >= 0",
                           format_number(std_H[i](k), 10) + " at " + format_number(freq_Hz(k), 10) + " Hz (index " +
                               std::to_string(k) + ")");
        }
      }
    }
  }
}

lti::FrequencyResponse to_frequency_response(const Frf& frf) {
  frf.validate();
  const Index n = frf.freq_Hz.size();
  const auto outputs = static_cast<Index>(frf.H.size());
  lti::FrequencyResponse r;
  r.omega = kTwoPi * frf.freq_Hz;
  r.H.assign(static_cast<std::size_t>(n), lti::CMatrix(outputs, 1));
  for (Index k = 0; k < n; ++k) {
    for (Index i = 0; i < outputs; ++i) r.H[static_cast<std::size_t>(k)](i, 0) = frf.H[static_cast<std::size_t>(i)](k);
  }
  return r;
}

Frf to_frf(const lti::FrequencyResponse& response, const std::string& input_name, const std::vector<std::string>& output_names,
           Index input) {
  const std::string src = "frequency response";
  const Index n = response.omega.size();
  if (response.H.size() != static_cast<std::size_t>(n)) {
    throw InputError(src, "H", std::to_string(n) + " matrices (one per frequency)", std::to_string(response.H.size()));
  }
  const auto outputs = static_cast<Index>(output_names.size());
  for (Index k = 0; k < n; ++k) {
    const lti::CMatrix& h = response.H[static_cast<std::size_t>(k)];
    if (h.rows() != outputs) {
      throw InputError(src, "outputs", std::to_string(h.rows()) + " names (one per output of the response)",
                       std::to_string(outputs) + " at index " + std::to_string(k));
    }
    if (input < 0 || input >= h.cols()) {
      throw InputError(src, "input", "an input index below " + std::to_string(h.cols()), std::to_string(input));
    }
  }
  Frf frf;
  frf.freq_Hz = response.omega / kTwoPi;
  frf.input = input_name;
  frf.outputs = output_names;
  frf.provenance.source = src;
  for (Index i = 0; i < outputs; ++i) {
    Eigen::VectorXcd h(n);
    for (Index k = 0; k < n; ++k) h(k) = response.H[static_cast<std::size_t>(k)](i, input);
    frf.H.push_back(std::move(h));
  }
  frf.validate(src);
  return frf;
}

Frf select_band(const Frf& frf, const BandSelection& selection) {
  std::vector<Index> outs = selection.outputs;
  if (outs.empty()) {
    for (std::size_t i = 0; i < frf.outputs.size(); ++i) outs.push_back(static_cast<Index>(i));
  }
  for (const Index i : outs) {
    if (i < 0 || static_cast<std::size_t>(i) >= frf.H.size()) {
      throw InputError(frf.provenance.source, "output", fmt::format("an output index below {}", frf.H.size()), std::to_string(i));
    }
  }
  // The coherence is known for every output or for none (Frf::validate).
  const auto known_coherence = [&](Index i) -> const Eigen::VectorXd* {
    return frf.coherence.empty() ? nullptr : &frf.coherence[static_cast<std::size_t>(i)];
  };
  std::vector<Index> keep;
  for (Index k = 0; k < frf.freq_Hz.size(); ++k) {
    const double f = frf.freq_Hz(k);
    if (f < selection.fmin_Hz || (selection.fmax_Hz > 0.0 && f > selection.fmax_Hz) || (selection.exclude_dc && f <= 0.0)) continue;
    const bool coherent = std::all_of(outs.begin(), outs.end(), [&](Index i) {
      const Eigen::VectorXd* c = known_coherence(i);
      return c == nullptr || (*c)(k) >= selection.min_coherence;
    });
    if (coherent) keep.push_back(k);
  }
  Frf band;
  band.input = frf.input;
  band.provenance = frf.provenance;
  band.freq_Hz = frf.freq_Hz(keep);
  for (const Index i : outs) {
    const auto ui = static_cast<std::size_t>(i);
    band.outputs.push_back(frf.outputs[ui]);
    band.H.emplace_back(frf.H[ui](keep));
    if (const Eigen::VectorXd* c = known_coherence(i)) band.coherence.emplace_back((*c)(keep));
    if (!frf.std_H.empty()) band.std_H.emplace_back(frf.std_H[ui](keep));
  }
  return band;
}

FrequencyBand excited_band(const Frf& frf, double min_coherence) {
  frf.validate();
  const Index n = frf.freq_Hz.size();
  FrequencyBand band;
  Index first_positive = 0;
  while (first_positive < n && frf.freq_Hz(first_positive) <= 0.0) ++first_positive;
  if (first_positive == n) throw InputError(frf.provenance.source, "freq_Hz", "a frequency above 0 Hz", "none");
  band.fmin_Hz = frf.freq_Hz(first_positive);
  band.fmax_Hz = frf.freq_Hz(n - 1);
  Eigen::VectorXd best = Eigen::VectorXd::Constant(n, -1.0);
  for (const auto& c : frf.coherence) {
    if (c.size() == n) best = best.cwiseMax(c);
  }
  if ((best.array() < 0.0).all()) return band;
  // Median over 9 neighbouring bins.
  std::vector<double> window;
  auto excited = [&](Index k) {
    if (best(k) < min_coherence) return false;
    window.clear();
    for (Index j = std::max(first_positive, k - 4); j <= std::min(n - 1, k + 4); ++j) window.push_back(best(j));
    std::nth_element(window.begin(), window.begin() + static_cast<std::ptrdiff_t>(window.size() / 2), window.end());
    return window[window.size() / 2] >= min_coherence;
  };
  Index lo = first_positive;
  while (lo < n && !excited(lo)) ++lo;
  if (lo == n) {
    throw InputError(frf.provenance.source, "coherence",
                     fmt::format("a band where the coherence reaches {} (the input excites the outputs)",
                                 format_number_exact(min_coherence)),
                     fmt::format("at most {}: check the input and output channels, or the excitation",
                                 format_number(best.maxCoeff(), 3)));
  }
  Index hi = n - 1;
  while (hi > lo && !excited(hi)) --hi;
  band.fmin_Hz = frf.freq_Hz(lo);
  band.fmax_Hz = frf.freq_Hz(hi);
  band.from_coherence = true;
  return band;
}

}  // namespace piezobench::dsp
