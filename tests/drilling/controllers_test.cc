#include "robomach/drilling/controllers.h"

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>

#include <gtest/gtest.h>

// Counts heap allocations so the test can check that Step() makes none.
static std::atomic<long> g_allocations{0};
void* operator new(std::size_t size) {
  ++g_allocations;
  if (void* p = std::malloc(size == 0 ? 1 : size)) return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }

namespace robomach::drilling {
namespace {

// A joint as a rigid inertia J with an unknown constant disturbance d:
// J q'' = tau + d, integrated exactly with tau held over each period.
struct DoubleIntegrator {
  double J, d, q{0.0}, v{0.0};
  void Step(double tau, double L) {
    const double a = (tau + d) / J;
    q += L * v + 0.5 * L * L * a;
    v += L * a;
  }
};

double RunLoop(JointController& c, DoubleIntegrator& p, int steps, double L) {
  Eigen::VectorXd zero = Eigen::VectorXd::Zero(1), q(1), tau(1);
  c.Reset(zero, zero);
  for (int k = 0; k < steps; ++k) {
    q(0) = p.q;
    c.Step(zero, zero, zero, q, q, &tau);
    p.Step(tau(0), L);
  }
  return p.q;
}

TEST(Controllers, PdLeavesTheClosedFormOffsetPidAndPdTdcRemoveIt) {
  const double L = 1e-3, J = 0.5, d = 2.0, w = 30.0;
  const Eigen::VectorXd lim = Eigen::VectorXd::Constant(1, 1e9);
  auto V = [](double x) { return Eigen::VectorXd::Constant(1, x); };
  // PD: at rest K_P e + d = 0, so q = -e = d / K_P.
  PidController pd({V(J * w * w), V(0.0), V(2 * J * w)}, lim, L);
  DoubleIntegrator p1{J, d};
  EXPECT_NEAR(RunLoop(pd, p1, 5000, L), d / (J * w * w), 1e-9);
  // PID: the integral takes up d.
  PidController pid({V(J * w * w), V(J * w * w * w / 4), V(2 * J * w)}, lim, L);
  DoubleIntegrator p2{J, d};
  EXPECT_NEAR(RunLoop(pid, p2, 8000, L), 0.0, 1e-9);
  // PD-TDC with Mbar = J: the delayed estimate takes up d within a period.
  PdTdcController tdc({V(w * w), V(2 * w), V(J)}, lim, L);
  DoubleIntegrator p3{J, d};
  EXPECT_NEAR(RunLoop(tdc, p3, 3000, L), 0.0, 1e-9);
}

TEST(Controllers, PidAntiWindupStopsIntegratingWhileSaturated) {
  // K_I = 10, limit 1: with e = 1 the output saturates once the integral
  // reaches 0.1 (after 10 periods of 10 ms). Without anti-windup the
  // integral would reach 1.0 after 100 periods and the output would stay
  // saturated (10 - 0.001) when the error flips to -0.01; with conditional
  // integration it leaves the limit at once: 10 (0.1 - 1e-4) < 1.
  const double L = 0.01;
  auto V = [](double x) { return Eigen::VectorXd::Constant(1, x); };
  PidController pid({V(0.0), V(10.0), V(0.0)}, V(1.0), L);
  Eigen::VectorXd zero = V(0.0), tau(1);
  pid.Reset(zero, zero);
  for (int k = 0; k < 100; ++k) pid.Step(V(1.0), zero, zero, zero, zero, &tau);
  EXPECT_DOUBLE_EQ(tau(0), 1.0);
  pid.Step(V(-0.01), zero, zero, zero, zero, &tau);
  EXPECT_LT(tau(0), 1.0);
  EXPECT_NEAR(tau(0), 10.0 * (0.1 - 1e-4), 1e-2);
}

TEST(Controllers, StepDoesNotAllocate) {
  const int n = 6;
  const Eigen::VectorXd one = Eigen::VectorXd::Ones(n), zero = Eigen::VectorXd::Zero(n);
  PidController pid({one, one, one}, 10 * one, 1e-3);
  PdTdcController tdc({one, one, one, 0.002}, 10 * one, 1e-3);
  Eigen::VectorXd q = 0.1 * one, tau(n);
  pid.Reset(zero, zero);
  tdc.Reset(zero, zero);
  const long before = g_allocations.load();
  for (int k = 0; k < 100; ++k) {
    pid.Step(zero, zero, zero, q, q, &tau);
    tdc.Step(zero, zero, zero, q, q, &tau);
  }
  EXPECT_EQ(g_allocations.load() - before, 0);
}

TEST(Controllers, TdeStabilityMeasureIsDistanceFromIdentity) {
  // Scalar case: |1 - Mbar / M|.
  Eigen::MatrixXd M(1, 1);
  M << 2.0;
  EXPECT_NEAR(TdeStabilityMeasure(M, Eigen::VectorXd::Constant(1, 1.0)), 0.5, 1e-15);
  EXPECT_NEAR(TdeStabilityMeasure(M, Eigen::VectorXd::Constant(1, 5.0)), 1.5, 1e-15);
  // Diagonal: the largest of the joint-wise measures.
  Eigen::MatrixXd M2 = Eigen::Vector2d(1.0, 4.0).asDiagonal();
  EXPECT_NEAR(TdeStabilityMeasure(M2, Eigen::Vector2d(0.5, 1.0)), 0.75, 1e-15);
}

}  // namespace
}  // namespace robomach::drilling
