// The physical floor of `piezobench frf FILE --input u --output de,Vs --nfft 10000 --overlap 0.5`
// as a whole process: read the whole file into memory with one read() into transparent huge pages,
// then one FFTW pass over the data: every segment of nfft samples (50 % overlap) of the last
// `channels` x `samples` doubles of the file, multiplied by a Hann window and transformed once
// (FFTW_ESTIMATE r2c plan, as piezobench's), nothing accumulated, no checks, no output but one
// number. Any program that reads the file and computes the spectra does at least this.
//   build/bench/dsp_frf_floor FILE [samples=6000000] [channels=3] [nfft=10000]
#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <fftw3.h>

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: dsp_frf_floor FILE [samples] [channels] [nfft]\n");
    return 2;
  }
  const long n = argc > 2 ? std::atol(argv[2]) : 6'000'000;
  const long channels = argc > 3 ? std::atol(argv[3]) : 3;
  const long nfft = argc > 4 ? std::atol(argv[4]) : 10'000;
  const int fd = open(argv[1], O_RDONLY);
  struct stat st {};
  if (fd < 0 || fstat(fd, &st) != 0) return 3;
  const auto size = static_cast<size_t>(st.st_size);
  if (size < static_cast<size_t>(channels * n) * sizeof(double)) return 3;
  void* mem = mmap(nullptr, size, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  if (mem == MAP_FAILED) return 4;
  (void)madvise(mem, size, MADV_HUGEPAGE);
  for (size_t got = 0; got < size;) {
    const ssize_t r = read(fd, static_cast<char*>(mem) + got, size - got);
    if (r <= 0) return 3;
    got += static_cast<size_t>(r);
  }
  close(fd);
  // The data: the last channels x n doubles (8-byte aligned as in a v5 file).
  const size_t first = (size - static_cast<size_t>(channels * n) * sizeof(double)) / 8 * 8;
  const double* data = reinterpret_cast<const double*>(static_cast<const char*>(mem) + first);

  double* in = fftw_alloc_real(static_cast<size_t>(nfft));
  fftw_complex* out = fftw_alloc_complex(static_cast<size_t>(nfft / 2 + 1));
  fftw_plan plan = fftw_plan_dft_r2c_1d(static_cast<int>(nfft), in, out, FFTW_ESTIMATE);
  double* window = fftw_alloc_real(static_cast<size_t>(nfft));
  for (long k = 0; k < nfft; ++k) window[k] = 0.5 - 0.5 * std::cos(2.0 * 3.14159265358979323846 * k / nfft);
  const long step = nfft / 2;
  double check = 0.0;
  long transforms = 0;
  for (long c = 0; c < channels; ++c) {
    const double* x = data + c * n;
    for (long s = 0; s + nfft <= n; s += step) {
      for (long k = 0; k < nfft; ++k) in[k] = window[k] * x[s + k];
      fftw_execute(plan);
      check += out[10][0];
      ++transforms;
    }
  }
  std::printf("%ld transforms of %ld, check %.6g\n", transforms, nfft, check);
  fftw_destroy_plan(plan);
  fftw_free(in);
  fftw_free(out);
  fftw_free(window);
  munmap(mem, size);
  return 0;
}
