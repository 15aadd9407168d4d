#include "stability/internal/batch_atan2.h"

#include <cmath>

#if defined(ROBOMACH_HAVE_LIBMVEC_ATAN2)
#include <immintrin.h>
// glibc's vector function ABI names of atan2: 2 doubles with SSE ('b', the
// x86-64 baseline) and 4 doubles with AVX2 ('d', chosen at run time).
extern "C" __m128d _ZGVbN2vv_atan2(__m128d y, __m128d x);
#if defined(__GNUC__) && defined(__x86_64__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpsabi"  // the AVX2 ABI is used only inside the target("avx2") function below
extern "C" __attribute__((target("avx2"))) __m256d _ZGVdN4vv_atan2(__m256d y, __m256d x);
#pragma GCC diagnostic pop
#define ROBOMACH_ATAN2_AVX2 1
#endif
#endif

namespace robomach::stability::internal {

namespace {

#if defined(ROBOMACH_ATAN2_AVX2)
__attribute__((target("avx2"))) long Atan2Avx2(const double* y, const double* x, double* out, long n) {
  long i = 0;
  for (; i + 4 <= n; i += 4) _mm256_storeu_pd(out + i, _ZGVdN4vv_atan2(_mm256_loadu_pd(y + i), _mm256_loadu_pd(x + i)));
  return i;
}

bool HasAvx2() {
  static const bool has = __builtin_cpu_supports("avx2");
  return has;
}
#endif

}  // namespace

void BatchAtan2(const double* y, const double* x, double* out, long n) {
  long i = 0;
#if defined(ROBOMACH_HAVE_LIBMVEC_ATAN2)
#if defined(ROBOMACH_ATAN2_AVX2)
  if (HasAvx2()) i = Atan2Avx2(y, x, out, n);
#endif
  for (; i + 2 <= n; i += 2) _mm_storeu_pd(out + i, _ZGVbN2vv_atan2(_mm_loadu_pd(y + i), _mm_loadu_pd(x + i)));
#endif
  for (; i < n; ++i) out[i] = std::atan2(y[i], x[i]);
}

bool BatchAtan2IsVectorised() {
#if defined(ROBOMACH_HAVE_LIBMVEC_ATAN2)
  return true;
#else
  return false;
#endif
}

}  // namespace robomach::stability::internal
