#include <gtest/gtest.h>

#include <cstdio>

#include "../tap_test_synth.h"
#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/modal_fit.h"

namespace robomach::calibration {
namespace {

TEST(TapProbe, Print) {
  for (int run = 0; run < 18; ++run) {
    const int K = std::vector<int>{1, 3, 15}[run % 3];
    testing::TapTestOptions o;
    o.seed = 100 + run / 3;
    o.drift_correlation_lines = std::abs(K);
    o.drift_flat_below_hz = 20;
    const testing::TapTest t = testing::MakeTapTest(o);
    const dynamics::Frf frf = dynamics::Frf::FromSamples(t.freq_hz, t.measured);
    const FrfNoise nm = EstimateFrfNoise(frf);
    std::printf("K=%d noise: %s\n", K, nm.description.c_str());
    dynamics::FrfSet set;
    set.Insert({"P1", Axis::kX, Axis::kX}, frf);
    const dynamics::FrfSet use = UsableData(set, {{{"P1", Axis::kX, Axis::kX}, nm}});
    const ModalFitResult r = FitModes(use.at({"P1", Axis::kX, Axis::kX}));
    std::printf("  seed %u fit: status %d, %s, order %d, misfit %g\n", int(r.status), o.seed, r.message.c_str(), r.order_used,
                r.relative_rms_error);
    for (const auto& m : r.modes) std::printf("   %.3f Hz  zeta %.5f  A %g%+gi\n", m.freq_hz, m.damping_ratio,
                                               m.modal_constant.real(), m.modal_constant.imag());
  }
}

}  // namespace
}  // namespace robomach::calibration
namespace robomach::calibration { namespace {
TEST(TapProbe, WriteCsv) {
  const testing::TapTest t = testing::MakeTapTest();
  testing::WriteTapTestCsv("/tmp/fit/tap18.csv", t, "P1", {"xx", "yy"});
  testing::WriteTapTestCsv("/tmp/fit/tap18_zz.csv", t, "T1", {"zz"});
}
}}
