#include "fft.hpp"

#include <string>
#include <vector>

#include <kiss_fftr.h>

#include "texel/error.hpp"

namespace texel::detail {

struct RealFft::Impl {
  kiss_fftr_cfg cfg = nullptr;
  std::vector<kiss_fft_scalar> in;
  std::vector<kiss_fft_cpx> out;
};

RealFft::RealFft(std::size_t n) : n_(n), impl_(std::make_unique<Impl>()) {
  if (n < 2 || n % 2 != 0 || n > (std::size_t{1} << 30))
    throw InvalidArgument("FFT length " + std::to_string(n) + " must be even and 2 … 2^30");
  impl_->cfg = kiss_fftr_alloc(static_cast<int>(n), 0, nullptr, nullptr);
  if (!impl_->cfg) throw std::bad_alloc();
  impl_->in.resize(n);
  impl_->out.resize(n / 2 + 1);
}

RealFft::~RealFft() {
  if (impl_ && impl_->cfg) kiss_fftr_free(impl_->cfg);
}

void RealFft::forward(std::span<const double> in, std::span<std::complex<double>> out) {
  for (std::size_t i = 0; i < n_; ++i) impl_->in[i] = static_cast<kiss_fft_scalar>(in[i]);
  kiss_fftr(impl_->cfg, impl_->in.data(), impl_->out.data());
  for (std::size_t k = 0; k <= n_ / 2; ++k) out[k] = {static_cast<double>(impl_->out[k].r), static_cast<double>(impl_->out[k].i)};
}

std::size_t fast_fft_length(std::size_t n) {
  if (n < 2) n = 2;
  for (std::size_t m = n + (n % 2);; m += 2) {
    std::size_t r = m;
    for (std::size_t p : {2u, 3u, 5u})
      while (r % p == 0) r /= p;
    if (r == 1) return m;
  }
}

}  // namespace texel::detail
