#pragma once

// The real-mode receptance sum of ReceptanceModal as a kernel over many
// frequency lines [Ewins 2000, §2.3]:
//   H_ij(ω) = Σ_k P_ij,k / (a_k + i b_k),  a_k = ω_k² − ω², b_k = c_k ω,
// with P_k = p_k p_kᵀ (six distinct entries, order xx yy zz xy xz yz) and
// c_k = 2 ζ_k ω_k. No complex division: 1/(a + ib) = (a − ib)/(a² + b²), one
// real division per line and mode, and the lines are processed in SIMD
// lanes (several lines at once, modes in the inner loop, the twelve sums in
// registers). On x86-64 the kernel exists twice: for the baseline (SSE2, two
// lines) and for AVX2+FMA (four lines), chosen at run time, because the
// library as a whole is built for the baseline (CMakeLists.txt: Debian's KDL
// and Eigen's alignment settings). Elsewhere a plain loop.
#include <complex>
#include <vector>

#include <Eigen/Core>

#include "robomach/dynamics/posture_dynamics.h"

namespace robomach::dynamics::internal {

enum class SimdLevel {
  kBest,      // AVX2+FMA when the CPU has it, else the baseline
  kBaseline,  // SSE2 on x86-64, plain C++ elsewhere
  kScalar,    // one line at a time, plain C++
};

/// True if kBest uses the AVX2+FMA kernel on this CPU.
bool ModalSumUsesAvx2();

/// The kernel's inputs from real modes: w2[k] = ω_k², c[k] = 2 ζ_k ω_k and
/// P[6k .. 6k + 5] = the six distinct entries of p_k p_kᵀ (xx yy zz xy xz yz).
/// The arrays hold modes.size() (w2, c) and 6 · modes.size() (P) values.
void PackModes(const std::vector<Mode>& modes, double* w2, double* c, double* P);

/// out[9 i .. 9 i + 8] = H at freq_hz[i] as a column-major 3×3 (the storage
/// of Eigen::Matrix3cd), for i in [0, num_lines).
/// @param w2, c, P  per mode k: ω_k² [rad²/s²], c_k [rad/s] and P.col(k).
void RealModalSum(int num_modes, const double* w2, const double* c, const double* P,
                  const double* freq_hz, Eigen::Index num_lines, std::complex<double>* out,
                  SimdLevel level = SimdLevel::kBest);

}  // namespace robomach::dynamics::internal
