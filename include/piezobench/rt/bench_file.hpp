#pragma once
// The bench description: which I/O backend drives the actuator, where each signal is wired, the
// amplifier and the limits that keep the actuator safe (docs/hardware.md "The bench file"; examples
// in docs/examples/bench-*.toml). Read and checked before anything moves: a hardware backend
// (comedi, udp) never starts without a file that sets the limits.
//
//   [bench]      name, backend ("virtual" | "udp" | "comedi"), sample_rate_Hz
//   [amplifier]  gain_V_per_V (stack volts per DAC volt, > 0)
//   [limits]     actuator, va_min_V, va_max_V, slew_rate_V_per_s (required for udp and comedi),
//                va_safe_V, ramp_s, stale_cycles, watchdog_s (optional)
//   [encoder]    resolution_m
//   [virtual]    unit, seed, twin ("FILE": a unit's digital twin, bench/twin.hpp)   (backend "virtual")
//   [udp]        address "HOST:PORT", timeout_s, key_file (the shared key; relative to the
//                bench file's folder)   (backend "udp")
//   [comedi]     device, calibration ("auto" | "soft" | "hard" | "none")   (backend "comedi")
//   [signals.u] [signals.d_e] [signals.Vs] [signals.Va]  (comedi; Va optional)
//                device (default comedi.device), subdevice, channel, range = [lo, hi] (V at the
//                converter), scale, unit, kind ("analog" | "counter", d_e only), aref
//                ("ground" | "common" | "diff", inputs)
// Scales: u: converter volts per volt of u (the DAC command); d_e: m per converter volt (analog)
// or m per count (counter; default encoder.resolution_m); Vs, Va: volts at the sensor or stacks per
// converter volt.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "piezobench/rt/safety.hpp"

namespace piezobench::rt {

struct SignalChannel {
  std::string device;       // e.g. /dev/comedi0
  int subdevice = -1;
  int channel = -1;
  double range_min = 0.0;   // V at the converter: the range the converter must cover
  double range_max = 0.0;   // V at the converter
  double scale = 1.0;       // see the file comment
  std::string unit;         // "V" (u, Vs, Va) or "m" (d_e)
  std::string kind = "analog";  // "analog" or "counter" (d_e only)
  std::string aref = "ground";  // analog reference of an input: "ground", "common" or "diff"
};

struct BenchDescription {
  std::string source;                 // the file, for messages
  std::string name;
  std::string backend = "virtual";    // "virtual", "udp" or "comedi"
  double sample_rate = 10e3;          // Hz
  ActuatorLimits limits;              // amplifier_gain included
  double encoder_resolution = 2.5e-9; // m per count
  // virtual
  int unit = 1;
  std::uint64_t seed = 1;
  std::string twin;                   // a digital twin file (bench/twin.hpp) instead of the batch
                                      // unit, resolved against the bench file's folder; "" = none
  // udp
  std::string udp_address;            // "127.0.0.1:5600"
  double udp_timeout = 2e-3;          // s: a reply later than this is a stale input
  std::string udp_key;                // the shared key's bytes (udp.key_file), empty: none
  // comedi
  std::string comedi_device = "/dev/comedi0";
  std::string calibration = "auto";
  SignalChannel u, de, vs;
  std::optional<SignalChannel> va;

  [[nodiscard]] bool hardware() const { return backend != "virtual"; }
  // InputError (source = the file) naming the field: the limits (ActuatorLimits::validate), a u
  // range that cannot express [va_min, va_max] / gain * scale, a u scale or amplifier gain of the
  // wrong sign (u -> Va must increase: the limits are mapped through it), a missing signal, a
  // channel number < 0, an empty range, a unit that is not the signal's.
  void validate() const;
};

// Reads and validates a bench file (InputError naming the file and key; unknown keys are errors).
BenchDescription read_bench_file(const std::filesystem::path& file);
// The same from TOML text; `source` names it in errors.
BenchDescription parse_bench_description(const std::string& text, const std::string& source);

}  // namespace piezobench::rt
