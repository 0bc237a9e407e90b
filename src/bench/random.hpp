#pragma once
// The bench's random numbers: xoshiro256** (D. Blackman and S. Vigna, "Scrambled linear
// pseudorandom number generators", ACM Trans. Math. Softw. 47(4), 2021), seeded through
// splitmix64 as its authors recommend. Integer arithmetic only, so a seed gives the same sequence
// on every platform and with every standard library.
//
// normal() is the sum of four 16-bit uniforms (Irwin-Hall), centred and scaled to unit variance:
// bounded at +-3.46, kurtosis 2.7 instead of 3, and about 2 ns per draw, which is what the bench's
// measurement noise needs (its inner loop must stay within a few tens of nanoseconds).
#include <cstdint>

namespace piezobench::bench::detail {

// One step of splitmix64 (Steele, Lea, Flood, "Fast splittable pseudorandom number generators",
// OOPSLA 2014): returns the next output and advances `state`.
inline std::uint64_t splitmix64(std::uint64_t& state) noexcept {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ULL);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ULL;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBULL;
  return z ^ (z >> 31);
}

// A seed for stream `stream` derived from `seed` (independent streams for units, experiments and
// instruments from one user seed).
inline std::uint64_t derive_seed(std::uint64_t seed, std::uint64_t stream) noexcept {
  std::uint64_t s = seed ^ (0xD1B54A32D192ED03ULL * (stream + 1));
  (void)splitmix64(s);
  return splitmix64(s);
}

class Xoshiro256 {
 public:
  explicit Xoshiro256(std::uint64_t seed = 1) noexcept { reseed(seed); }

  void reseed(std::uint64_t seed) noexcept {
    std::uint64_t sm = seed;
    for (auto& w : s_) w = splitmix64(sm);
  }
  // The raw state, for tests against the reference implementation.
  void set_state(std::uint64_t a, std::uint64_t b, std::uint64_t c, std::uint64_t d) noexcept {
    s_[0] = a;
    s_[1] = b;
    s_[2] = c;
    s_[3] = d;
  }

  std::uint64_t next() noexcept {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9;
    const std::uint64_t t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }

  // Uniform in [0, 1) with 53 random bits.
  double uniform() noexcept { return static_cast<double>(static_cast<std::int64_t>(next() >> 11)) * 0x1.0p-53; }
  // Uniform in [-1, 1).
  double symmetric() noexcept { return 2.0 * uniform() - 1.0; }

  // Two approximately standard normal values from one draw: each the sum of four 8-bit uniforms,
  // centred and scaled (the same Irwin-Hall shape at a resolution of 0.7 % of sigma, which is finer
  // than any quantization it is followed by). For measurement noise, half the cost of normal().
  void normal_pair(double& a, double& b) noexcept {
    const std::uint64_t r = next();
    // Add the bytes of each 32-bit half with SWAR: pairs of bytes, then pairs of 16-bit sums.
    std::uint64_t s = (r & 0x00FF00FF00FF00FFULL) + ((r >> 8) & 0x00FF00FF00FF00FFULL);
    s = (s & 0x0000FFFF0000FFFFULL) + ((s >> 16) & 0x0000FFFF0000FFFFULL);
    // Each 8-bit uniform on {0..255} has mean 127.5 and variance (256^2 - 1) / 12.
    constexpr double kMean = 4.0 * 127.5;
    constexpr double kScale = 0.006765875086793228;  // 1 / sqrt(4 (256^2 - 1) / 12)
    // (Through int64: an unsigned 64-bit conversion costs a branch on x86-64 without AVX-512.)
    a = (static_cast<double>(static_cast<std::int64_t>(s & 0xFFFFFFFFULL)) - kMean) * kScale;
    b = (static_cast<double>(static_cast<std::int64_t>(s >> 32)) - kMean) * kScale;
  }

  // Approximately standard normal (see the file comment).
  double normal() noexcept {
    const std::uint64_t r = next();
    const auto sum = static_cast<double>(
        static_cast<std::int64_t>((r & 0xFFFF) + ((r >> 16) & 0xFFFF) + ((r >> 32) & 0xFFFF) + (r >> 48)));
    // Each 16-bit uniform on {0..65535} has mean 32767.5 and variance (65536^2 - 1) / 12.
    constexpr double kMean = 4.0 * 32767.5;
    constexpr double kScale = 2.6428997921303014e-05;  // 1 / sqrt(4 (65536^2 - 1) / 12)
    return (sum - kMean) * kScale;
  }

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) noexcept { return (x << k) | (x >> (64 - k)); }
  std::uint64_t s_[4]{};
};

}  // namespace piezobench::bench::detail
