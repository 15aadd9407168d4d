// Quadrature decoding (formats.md §8.2) against hand-written sequences and
// against an independent encoder: random walks, written out as (A,B) levels
// from the Gray sequence of the format, must decode to exactly the walk.
#include "robomach/machine/quadrature_decoder.h"

#include <gtest/gtest.h>

#include <random>
#include <vector>

namespace robomach::machine {
namespace {

// (A,B) levels of phase 0..3 as formats.md §8.2 writes them:
// (0,0) -> (1,0) -> (1,1) -> (0,1) is the + direction.
constexpr int kA[4] = {0, 1, 1, 0};
constexpr int kB[4] = {0, 0, 1, 1};

std::uint16_t Word(const std::vector<int>& a, const std::vector<int>& b) {
  std::uint16_t w = 0;
  for (size_t k = 0; k < a.size(); ++k) w |= static_cast<std::uint16_t>((a[k] << (2 * k)) | (b[k] << (2 * k + 1)));
  return w;
}

// One axis given as a string of "AB" pairs, e.g. {"00","10","11"}.
std::vector<std::uint16_t> OneAxis(const std::vector<const char*>& ab) {
  std::vector<std::uint16_t> w;
  for (const char* s : ab) w.push_back(static_cast<std::uint16_t>((s[0] - '0') | ((s[1] - '0') << 1)));
  return w;
}

QuadratureDecoder DecodeAll(const std::vector<std::uint16_t>& w, QuadratureOptions o = {.num_axes = 1}) {
  QuadratureDecoder d(o);
  d.Decode(w);
  return d;
}

TEST(QuadratureDecoder, UpCountsOnePerEdge) {
  const auto d = DecodeAll(OneAxis({"00", "10", "11", "01", "00", "10", "11"}));
  EXPECT_EQ(d.count(0), 6);
  EXPECT_EQ(d.error_events()[0], 0);
  EXPECT_EQ(d.samples(), 7);
}

TEST(QuadratureDecoder, DownCountsMinusOnePerEdge) {
  const auto d = DecodeAll(OneAxis({"00", "01", "11", "10", "00", "01"}));
  EXPECT_EQ(d.count(0), -5);
  EXPECT_EQ(d.error_events()[0], 0);
}

TEST(QuadratureDecoder, ReversalAndHolds) {
  // +1 +1 (hold) -1 -1 -1 +1: net 0, with repeated samples counting nothing.
  const auto d = DecodeAll(OneAxis({"00", "10", "11", "11", "11", "10", "00", "01", "00"}));
  EXPECT_EQ(d.count(0), 0);
  EXPECT_EQ(d.error_events()[0], 0);
}

TEST(QuadratureDecoder, IllegalEventCountsNothingAndContinuesFromNewState) {
  // 00 -> 11 is a double change: no count, one error; then 11 -> 01 is +1
  // from the new state, 01 -> 10 another error, 10 -> 11 +1.
  const auto d = DecodeAll(OneAxis({"00", "11", "01", "10", "11"}));
  EXPECT_EQ(d.count(0), 2);
  EXPECT_EQ(d.error_events()[0], 2);
}

TEST(QuadratureDecoder, GlitchOnAWithoutFilterCancels) {
  // A pulses for one sample while B sits still: +1 then -1.
  const auto d = DecodeAll(OneAxis({"00", "10", "00", "00", "10", "11"}));
  EXPECT_EQ(d.count(0), 2);
}

TEST(QuadratureDecoder, GlitchFilterRejectsShortPulsesOnAAndB) {
  // Filter of 3 samples: a 1-sample pulse on A and a 2-sample pulse on B are
  // rejected; the A edge that holds 3 samples is accepted, then B's.
  const std::vector<std::uint16_t> w =
      OneAxis({"00", "10", "00", "01", "01", "00", "10", "10", "10", "11", "11", "11"});
  const auto filtered = DecodeAll(w, {.num_axes = 1, .glitch_filter_samples = 3});
  EXPECT_EQ(filtered.count(0), 2);
  EXPECT_EQ(filtered.error_events()[0], 0);
  // Unfiltered, the same samples count every edge: +1-1 -1 +1 (hold) +1 +1 = 2,
  // but through 7 more transitions.
  EXPECT_EQ(DecodeAll(w).count(0), 2);
}

TEST(QuadratureDecoder, GlitchFilterTurnsAGlitchDuringAnEdgeIntoNothing) {
  // Without filter, a B glitch in the sample where A rises makes a double
  // change (error event); with a 2-sample filter it is ignored.
  const std::vector<std::uint16_t> w = OneAxis({"00", "00", "11", "10", "10", "10"});
  const auto raw = DecodeAll(w);
  EXPECT_EQ(raw.error_events()[0], 1);
  const auto f = DecodeAll(w, {.num_axes = 1, .glitch_filter_samples = 2});
  EXPECT_EQ(f.count(0), 1);
  EXPECT_EQ(f.error_events()[0], 0);
}

TEST(QuadratureDecoder, AxesAreIndependentAndMaskedToTheirBits) {
  // Axis 0 up, axis 1 down, bits above the 2 axes toggle and must be ignored.
  std::vector<std::uint16_t> w;
  for (int s = 0; s < 9; ++s) {
    const int p0 = s % 4, p1 = (4 - s % 4) % 4;
    w.push_back(static_cast<std::uint16_t>(Word({kA[p0], kA[p1]}, {kB[p0], kB[p1]}) | ((s & 1) ? 0xFFF0 : 0)));
  }
  const auto d = DecodeAll(w, {.num_axes = 2});
  EXPECT_EQ(d.count(0), 8);
  EXPECT_EQ(d.count(1), -8);
  EXPECT_EQ(d.error_events()[0] + d.error_events()[1], 0);
}

TEST(QuadratureDecoder, RejectsBadOptions) {
  EXPECT_THROW(QuadratureDecoder({.num_axes = 0}), std::invalid_argument);
  EXPECT_THROW(QuadratureDecoder({.num_axes = 9}), std::invalid_argument);
  EXPECT_THROW(QuadratureDecoder({.num_axes = 5, .glitch_filter_samples = -1}), std::invalid_argument);
}

// Random walks of 5 axes from each of the four start phases; steps of -1, 0,
// +1 per sample. Decoded in blocks of random sizes, the count after every
// block equals the walk exactly, with no error event.
TEST(QuadratureDecoder, RandomWalksFromEachStartPhaseRoundTripExactly) {
  for (int start = 0; start < 4; ++start) {
    for (int filter : {0, 1}) {
      std::mt19937 rng(100 + start);
      std::uniform_int_distribution<int> step(-1, 1);
      const int n = 20000, axes = 5;
      std::vector<int> phase(axes, start);
      std::vector<std::vector<long>> truth(n, std::vector<long>(axes, 0));
      std::vector<std::uint16_t> words(n);
      std::vector<long> c(axes, 0);
      for (int s = 0; s < n; ++s) {
        if (s > 0) {
          for (int k = 0; k < axes; ++k) {
            const int d = step(rng);
            c[k] += d;
            phase[k] = (phase[k] + d + 4) % 4;
          }
        }
        truth[s].assign(c.begin(), c.end());
        std::vector<int> a(axes), b(axes);
        for (int k = 0; k < axes; ++k) a[k] = kA[phase[k]], b[k] = kB[phase[k]];
        words[s] = Word(a, b);
      }
      QuadratureDecoder d({.num_axes = axes, .glitch_filter_samples = filter});
      std::uniform_int_distribution<int> block(1, 700);
      size_t at = 0;
      while (at < words.size()) {
        const size_t len = std::min<size_t>(block(rng), words.size() - at);
        d.Decode(words.data() + at, len);
        at += len;
        for (int k = 0; k < axes; ++k) {
          ASSERT_EQ(d.count(k), truth[at - 1][k]) << "start phase " << start << ", sample " << at - 1;
        }
      }
      for (int k = 0; k < axes; ++k) EXPECT_EQ(d.error_events()[k], 0);
      EXPECT_EQ(d.samples(), n);
    }
  }
}

// A walk that moves at most one step every 4 samples, with single-sample
// glitches on A or B sprinkled where the axis is idle: a 2-sample filter
// recovers the walk exactly, without error events.
TEST(QuadratureDecoder, GlitchFilterRecoversWalkWithGlitches) {
  std::mt19937 rng(7);
  const int n = 40000, axes = 5;
  std::vector<int> phase(axes, 2);
  std::vector<long> c(axes, 0);
  std::vector<std::uint16_t> words(n);
  std::uniform_int_distribution<int> step(-1, 1);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  for (int s = 0; s < n; ++s) {
    if (s > 0 && s % 4 == 0) {
      for (int k = 0; k < axes; ++k) {
        const int d = step(rng);
        c[k] += d;
        phase[k] = (phase[k] + d + 4) % 4;
      }
    }
    std::vector<int> a(axes), b(axes);
    for (int k = 0; k < axes; ++k) a[k] = kA[phase[k]], b[k] = kB[phase[k]];
    words[s] = Word(a, b);
    // Glitch at s % 4 == 2 (steps happen at s % 4 == 0): a one-sample pulse.
    if (s % 4 == 2 && u(rng) < 0.3) words[s] ^= static_cast<std::uint16_t>(1u << (rng() % (2 * axes)));
  }
  QuadratureDecoder d({.num_axes = axes, .glitch_filter_samples = 2});
  d.Decode(words);
  for (int k = 0; k < axes; ++k) {
    EXPECT_EQ(d.count(k), c[k]) << "axis " << k;
    EXPECT_EQ(d.error_events()[k], 0);
  }
}

}  // namespace
}  // namespace robomach::machine
