#include "robomach/machine/quadrature_decoder.h"

#include <algorithm>
#include <bit>
#include <cstring>
#include <stdexcept>
#include <string>

#include "robomach/common/option_checks.h"

namespace robomach::machine {
namespace {

// Channel code of one axis: A + 2 B. The +1 direction visits the codes
// 0 (A0 B0) -> 1 (A1 B0) -> 3 (A1 B1) -> 2 (A0 B1) -> 0, i.e. phases 0,1,2,3.
constexpr int kPhaseOfCode[4] = {0, 1, 3, 2};

struct TransitionTable {
  std::int8_t delta[16];  // index (from << 2) | to
  std::int8_t error[16];
};

constexpr TransitionTable MakeTable() {
  TransitionTable t{};
  for (int from = 0; from < 4; ++from) {
    for (int to = 0; to < 4; ++to) {
      const int step = (kPhaseOfCode[to] - kPhaseOfCode[from] + 4) % 4;
      const int i = (from << 2) | to;
      t.delta[i] = step == 1 ? 1 : step == 3 ? -1 : 0;
      t.error[i] = step == 2 ? 1 : 0;  // both channels changed: direction unknown
    }
  }
  return t;
}

constexpr TransitionTable kTable = MakeTable();

// delta + error * 2^32 in one 64-bit addend, so the hot loop does one table
// lookup and one add per axis; unpacked at the end of a run of fewer than
// 2^31 samples (|sum of deltas| < 2^31 then).
struct PackedTable {
  std::int64_t v[16];
};
constexpr PackedTable MakePacked() {
  PackedTable p{};
  for (int i = 0; i < 16; ++i) p.v[i] = static_cast<std::int64_t>(kTable.delta[i]) + (static_cast<std::int64_t>(kTable.error[i]) << 32);
  return p;
}
constexpr PackedTable kPacked = MakePacked();

}  // namespace

void QuadratureOptions::Validate() const {
  CheckOptionRange("num_axes", num_axes, 1, kMaxQuadratureAxes);
  CheckOptionRange("glitch_filter_samples", glitch_filter_samples, 0, 1000000);
}

QuadratureDecoder::QuadratureDecoder(const QuadratureOptions& options) : options_(options) {
  options.Validate();
  mask_ = (options.num_axes == 8) ? 0xFFFFu : ((1u << (2 * options.num_axes)) - 1u);
  counts_.assign(options.num_axes, 0);
  errors_.assign(options.num_axes, 0);
  run_.assign(2 * options.num_axes, 0);
}

inline void QuadratureDecoder::Transition(std::uint32_t from, std::uint32_t to) {
  std::uint32_t changed = from ^ to;
  while (changed != 0) {
    const int k = std::countr_zero(changed) >> 1;  // axis whose channels changed
    const int shift = 2 * k;
    const int i = static_cast<int>((((from >> shift) & 3u) << 2) | ((to >> shift) & 3u));
    counts_[k] += kTable.delta[i];
    errors_[k] += kTable.error[i];
    changed &= ~(3u << shift);
  }
}

void QuadratureDecoder::Decode(const std::uint16_t* words, std::size_t n) {
  if (n == 0) return;
  if (samples_ == 0) {  // the reference state
    state_ = words[0] & mask_;
    ++words;
    --n;
    samples_ = 1;
  }
  if (options_.glitch_filter_samples <= 1) {
    DecodeUnfiltered(words, n);
  } else {
    DecodeFiltered(words, n);
  }
  samples_ += static_cast<std::int64_t>(n);
}

namespace {

// The decoding loop for a fixed number of axes, so that the per-axis work is
// unrolled and branch-free: runs of unchanged samples are skipped four at a
// time (the common case at MHz sampling rates); a group of four samples with
// any change goes through the transition table axis by axis without a branch.
template <int N>
std::uint32_t DecodeFixed(const std::uint16_t* words, std::size_t n, std::uint32_t state,
                          std::int64_t* counts, std::int64_t* errors) {
  constexpr std::uint32_t kMask = N == 8 ? 0xFFFFu : ((1u << (2 * N)) - 1u);
  constexpr std::uint64_t kMask4 = static_cast<std::uint64_t>(kMask) * 0x0001000100010001ull;
  constexpr std::size_t kRun = std::size_t{1} << 30;  // keeps the packed deltas below 2^31
  for (std::size_t start = 0; start < n; start += kRun) {
    const std::size_t end_all = std::min(n, start + kRun);
    std::int64_t acc[N];
    for (int k = 0; k < N; ++k) acc[k] = 0;
    std::size_t i = start;
    while (i < end_all) {
      const std::uint64_t rep = static_cast<std::uint64_t>(state) * 0x0001000100010001ull;
      while (i + 4 <= end_all) {
        std::uint64_t four;
        std::memcpy(&four, words + i, 8);
        if (((four ^ rep) & kMask4) != 0) break;
        i += 4;
      }
      const std::size_t end = std::min(end_all, i + 4);
      for (; i < end; ++i) {
        const std::uint32_t w = words[i] & kMask;
        // Per axis: index (old code << 2) | new code, from the two words.
        for (int k = 0; k < N; ++k) {
          const unsigned t = (((state >> (2 * k)) & 3u) << 2) | ((w >> (2 * k)) & 3u);
          acc[k] += kPacked.v[t];
        }
        state = w;
      }
    }
    for (int k = 0; k < N; ++k) {
      const std::int64_t e = (acc[k] + (std::int64_t{1} << 31)) >> 32;
      errors[k] += e;
      counts[k] += acc[k] - (e << 32);
    }
  }
  return state;
}

}  // namespace

void QuadratureDecoder::DecodeUnfiltered(const std::uint16_t* words, std::size_t n) {
  std::int64_t* c = counts_.data();
  std::int64_t* e = errors_.data();
  switch (options_.num_axes) {
    case 1: state_ = DecodeFixed<1>(words, n, state_, c, e); break;
    case 2: state_ = DecodeFixed<2>(words, n, state_, c, e); break;
    case 3: state_ = DecodeFixed<3>(words, n, state_, c, e); break;
    case 4: state_ = DecodeFixed<4>(words, n, state_, c, e); break;
    case 5: state_ = DecodeFixed<5>(words, n, state_, c, e); break;
    case 6: state_ = DecodeFixed<6>(words, n, state_, c, e); break;
    case 7: state_ = DecodeFixed<7>(words, n, state_, c, e); break;
    default: state_ = DecodeFixed<8>(words, n, state_, c, e); break;
  }
}

void QuadratureDecoder::DecodeFiltered(const std::uint16_t* words, std::size_t n) {
  const int need = options_.glitch_filter_samples;
  for (std::size_t i = 0; i < n; ++i) {
    const std::uint32_t raw = words[i] & mask_;
    const std::uint32_t differs = raw ^ state_;
    // Channels that came back to the accepted level: the candidate was a glitch.
    std::uint32_t reset = pending_ & ~differs;
    while (reset != 0) {
      const int b = std::countr_zero(reset);
      run_[b] = 0;
      reset &= reset - 1;
    }
    pending_ &= differs;
    std::uint32_t flip = 0;
    std::uint32_t d = differs;
    while (d != 0) {
      const int b = std::countr_zero(d);
      if (++run_[b] >= need) {
        flip |= 1u << b;
        run_[b] = 0;
      }
      d &= d - 1;
    }
    pending_ |= differs & ~flip;
    if (flip != 0) {
      const std::uint32_t next = state_ ^ flip;
      Transition(state_, next);
      state_ = next;
    }
  }
}

}  // namespace robomach::machine
