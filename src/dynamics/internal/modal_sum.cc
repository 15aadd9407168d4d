#include "dynamics/internal/modal_sum.h"

#include "robomach/common/units.h"

#if defined(__x86_64__) && (defined(__GNUC__) || defined(__clang__))
#define ROBOMACH_MODAL_SUM_X86 1
#include <immintrin.h>
#else
#define ROBOMACH_MODAL_SUM_X86 0
#endif

namespace robomach::dynamics::internal {

void PackModes(const std::vector<Mode>& modes, double* w2, double* c, double* P) {
  for (size_t k = 0; k < modes.size(); ++k) {
    const double w = HzToRadPerSec(modes[k].freq_hz);
    w2[k] = w * w;
    c[k] = 2.0 * modes[k].damping_ratio * w;
    const Eigen::Vector3d& p = modes[k].p_T;
    double* Pk = P + 6 * k;
    Pk[0] = p(0) * p(0);
    Pk[1] = p(1) * p(1);
    Pk[2] = p(2) * p(2);
    Pk[3] = p(0) * p(1);
    Pk[4] = p(0) * p(2);
    Pk[5] = p(1) * p(2);
  }
}
namespace {

// Column-major 3×3 position s → which of the six distinct entries.
constexpr int kSlot[9] = {0, 3, 4, 3, 1, 5, 4, 5, 2};
constexpr double kTwoPi = 2.0 * kPi;  // ω = f·2π, as HzToRadPerSec (exact scaling by 2)

void ScalarLines(int nm, const double* w2, const double* c, const double* P, const double* f,
                 Eigen::Index first, Eigen::Index last, double* out) {
  for (Eigen::Index i = first; i < last; ++i) {
    const double w = f[i] * kTwoPi, w_sq = w * w;
    double re[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0}, im[6] = {0.0, 0.0, 0.0, 0.0, 0.0, 0.0};
    for (int k = 0; k < nm; ++k) {
      const double a = w2[k] - w_sq, b = c[k] * w;
      const double inv = 1.0 / (a * a + b * b);
      const double ar = a * inv, bi = b * inv;
      for (int j = 0; j < 6; ++j) {
        re[j] += ar * P[6 * k + j];
        im[j] -= bi * P[6 * k + j];
      }
    }
    double* o = out + 18 * i;
    for (int s = 0; s < 9; ++s) {
      o[2 * s] = re[kSlot[s]];
      o[2 * s + 1] = im[kSlot[s]];
    }
  }
}

#if ROBOMACH_MODAL_SUM_X86

// Two lines per step in SSE2 registers (the x86-64 baseline).
void Sse2Lines(int nm, const double* w2, const double* c, const double* P, const double* f, Eigen::Index L,
               double* out) {
  Eigen::Index i = 0;
  const __m128d two_pi = _mm_set1_pd(kTwoPi), one = _mm_set1_pd(1.0);
  for (; i + 2 <= L; i += 2) {
    const __m128d w = _mm_mul_pd(_mm_loadu_pd(f + i), two_pi), w_sq = _mm_mul_pd(w, w);
    __m128d re[6], im[6];
    for (int j = 0; j < 6; ++j) re[j] = im[j] = _mm_setzero_pd();
    for (int k = 0; k < nm; ++k) {
      const __m128d a = _mm_sub_pd(_mm_set1_pd(w2[k]), w_sq), b = _mm_mul_pd(_mm_set1_pd(c[k]), w);
      const __m128d inv = _mm_div_pd(one, _mm_add_pd(_mm_mul_pd(a, a), _mm_mul_pd(b, b)));
      const __m128d ar = _mm_mul_pd(a, inv), bi = _mm_mul_pd(b, inv);
      for (int j = 0; j < 6; ++j) {
        const __m128d p = _mm_set1_pd(P[6 * k + j]);
        re[j] = _mm_add_pd(re[j], _mm_mul_pd(ar, p));
        im[j] = _mm_sub_pd(im[j], _mm_mul_pd(bi, p));
      }
    }
    // (re, im) of line i in the low lanes, of line i + 1 in the high ones.
    double* o = out + 18 * i;
    for (int s = 0; s < 9; ++s) {
      const int j = kSlot[s];
      _mm_storeu_pd(o + 2 * s, _mm_unpacklo_pd(re[j], im[j]));
      _mm_storeu_pd(o + 18 + 2 * s, _mm_unpackhi_pd(re[j], im[j]));
    }
  }
  ScalarLines(nm, w2, c, P, f, i, L, out);
}

// Four lines per step in AVX2 registers; the compiler may fuse the
// multiply-adds (rounding differs from the baseline by ~1 ulp per term).
__attribute__((target("avx2,fma"))) void Avx2Lines(int nm, const double* w2, const double* c, const double* P,
                                                   const double* f, Eigen::Index L, double* out) {
  Eigen::Index i = 0;
  const __m256d two_pi = _mm256_set1_pd(kTwoPi), one = _mm256_set1_pd(1.0);
  for (; i + 4 <= L; i += 4) {
    const __m256d w = _mm256_mul_pd(_mm256_loadu_pd(f + i), two_pi), w_sq = _mm256_mul_pd(w, w);
    __m256d re[6], im[6];
    for (int j = 0; j < 6; ++j) re[j] = im[j] = _mm256_setzero_pd();
    for (int k = 0; k < nm; ++k) {
      const __m256d a = _mm256_sub_pd(_mm256_set1_pd(w2[k]), w_sq), b = _mm256_mul_pd(_mm256_set1_pd(c[k]), w);
      const __m256d inv = _mm256_div_pd(one, _mm256_add_pd(_mm256_mul_pd(a, a), _mm256_mul_pd(b, b)));
      const __m256d ar = _mm256_mul_pd(a, inv), bi = _mm256_mul_pd(b, inv);
      for (int j = 0; j < 6; ++j) {
        const __m256d p = _mm256_set1_pd(P[6 * k + j]);
        re[j] = _mm256_add_pd(re[j], _mm256_mul_pd(ar, p));
        im[j] = _mm256_sub_pd(im[j], _mm256_mul_pd(bi, p));
      }
    }
    // unpacklo: (re, im) of lines i and i + 2; unpackhi: of lines i + 1 and i + 3.
    double* o = out + 18 * i;
    for (int s = 0; s < 9; ++s) {
      const int j = kSlot[s];
      const __m256d lo = _mm256_unpacklo_pd(re[j], im[j]), hi = _mm256_unpackhi_pd(re[j], im[j]);
      _mm_storeu_pd(o + 2 * s, _mm256_castpd256_pd128(lo));
      _mm_storeu_pd(o + 18 + 2 * s, _mm256_castpd256_pd128(hi));
      _mm_storeu_pd(o + 36 + 2 * s, _mm256_extractf128_pd(lo, 1));
      _mm_storeu_pd(o + 54 + 2 * s, _mm256_extractf128_pd(hi, 1));
    }
  }
  ScalarLines(nm, w2, c, P, f, i, L, out);
}

#endif

}  // namespace

bool ModalSumUsesAvx2() {
#if ROBOMACH_MODAL_SUM_X86
  static const bool has = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  return has;
#else
  return false;
#endif
}

void RealModalSum(int nm, const double* w2, const double* c, const double* P, const double* f, Eigen::Index L,
                  std::complex<double>* out_complex, SimdLevel level) {
  // std::complex<double> is two doubles (re, im) by the standard's layout rule.
  double* out = reinterpret_cast<double*>(out_complex);
  if (level == SimdLevel::kScalar) return ScalarLines(nm, w2, c, P, f, 0, L, out);
#if ROBOMACH_MODAL_SUM_X86
  if (level == SimdLevel::kBest && ModalSumUsesAvx2()) return Avx2Lines(nm, w2, c, P, f, L, out);
  return Sse2Lines(nm, w2, c, P, f, L, out);
#else
  return ScalarLines(nm, w2, c, P, f, 0, L, out);
#endif
}

}  // namespace robomach::dynamics::internal
