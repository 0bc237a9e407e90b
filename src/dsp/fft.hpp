#pragma once
// Private: FFTW plans shared by the module and the aligned buffers they run on.
//
// FFTW's planner is not thread-safe, its executor is (fftw_execute_dft_r2c on new arrays). Plans
// are therefore made once per length under a mutex, kept for the life of the process, and
// executed on buffers from fftw_malloc (the alignment the plan was made for).
#include <Eigen/Dense>
#include <complex>
#include <cstddef>
#include <future>
#include <memory>

namespace piezobench::dsp::detail {

struct FftwFree {
  void operator()(void* p) const;
};

// kNone: for a buffer that is written whole before it is read (a transform's output, samples
// drawn into it): no pass over fresh pages.
enum class BufferInit { kZero, kNone };

// An fftw_malloc'ed array of n elements (zero-initialized unless BufferInit::kNone).
template <typename T>
class FftwBuffer {
 public:
  FftwBuffer() = default;
  explicit FftwBuffer(Eigen::Index n, BufferInit init = BufferInit::kZero);
  [[nodiscard]] T* data() { return data_.get(); }
  [[nodiscard]] const T* data() const { return data_.get(); }
  [[nodiscard]] Eigen::Index size() const { return size_; }
  T& operator[](Eigen::Index i) { return data_.get()[i]; }
  const T& operator[](Eigen::Index i) const { return data_.get()[i]; }

 private:
  std::unique_ptr<T, FftwFree> data_;
  Eigen::Index size_ = 0;
};

// Real-to-complex forward DFT of length n: out[k] = sum_j in[j] exp(-2 pi i j k / n),
// k = 0 .. n/2 (n/2 + 1 outputs). `in` is not modified.
class RealForwardFft {
 public:
  explicit RealForwardFft(Eigen::Index n);  // fetches (or makes) the shared plan
  [[nodiscard]] Eigen::Index size() const { return n_; }
  [[nodiscard]] Eigen::Index bins() const { return n_ / 2 + 1; }
  // Both arrays must come from FftwBuffer.
  void execute(const double* in, std::complex<double>* out) const;

 private:
  Eigen::Index n_;
  const void* plan_;
};

// Complex-to-real inverse DFT of length n (unnormalized): out[j] = sum_k c[k] exp(+2 pi i j k / n)
// over the full Hermitian spectrum whose first n/2 + 1 entries are given. `in` is destroyed.
class RealInverseFft {
 public:
  explicit RealInverseFft(Eigen::Index n);
  [[nodiscard]] Eigen::Index size() const { return n_; }
  void execute(std::complex<double>* in, double* out) const;

 private:
  Eigen::Index n_;
  const void* plan_;
};

// Makes (or finds) the plans of length n in `directions` on another thread, for a caller with
// other work to do meanwhile: a 1 M-point plan costs milliseconds (its twiddle factors). get() on
// the result waits for them and rethrows a planning failure. Short lengths (or no thread to be
// had) are planned by get() itself.
enum class PlanDirections { kForward, kInverse, kBoth };
[[nodiscard]] std::future<void> plan_in_background(Eigen::Index n, PlanDirections directions = PlanDirections::kBoth);

// Convenience on Eigen vectors (copies into aligned buffers): full one-sided spectrum of x, and
// the real signal of length n from its one-sided spectrum (normalized by 1/n, i.e. numpy irfft).
Eigen::VectorXcd rfft(const Eigen::VectorXd& x);
Eigen::VectorXd irfft(const Eigen::VectorXcd& spectrum, Eigen::Index n);

}  // namespace piezobench::dsp::detail
