#pragma once

// atan2 over arrays. Where glibc's vector math library (libmvec, glibc
// 2.35+) is found at configure time, two lanes at a time through its
// SSE2-ABI entry _ZGVbN2vv_atan2, which picks the best kernel for the CPU
// at run time (the ZOA's phases were 9 % of a stability map with scalar
// atan2); std::atan2 otherwise. libmvec's atan2 is accurate to a few ulp
// (glibc manual, "Errors in Math Functions"), against std::atan2's one:
// tests/stability/zoa_lobes_test.cc compares the two.
namespace robomach::stability::internal {

/// out[i] = atan2(y[i], x[i]) for i < n. The arrays may not overlap `out`.
void BatchAtan2(const double* y, const double* x, double* out, long n);

/// Whether BatchAtan2 uses libmvec (for tests and benchmarks).
bool BatchAtan2IsVectorised();

}  // namespace robomach::stability::internal
