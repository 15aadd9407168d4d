#pragma once
// 4x quadrature decoding of a raw capture (formats.md §8.2), block by block in
// constant memory, so that a file of any size or a live acquisition card can
// feed it.

#include <cstddef>
#include <cstdint>
#include <span>
#include <vector>

namespace robomach::machine {

/// Bit 2k of a capture word is channel A and bit 2k+1 channel B of axis k.
inline constexpr int kMaxQuadratureAxes = 8;

struct QuadratureOptions {
  int num_axes{5};                 // 1 .. kMaxQuadratureAxes
  /// Glitch filter: a new level of a channel is accepted only once it has
  /// been seen on N consecutive samples (it then takes effect at the N-th of
  /// them, i.e. N - 1 samples late). 0 or 1 switches the filter off.
  int glitch_filter_samples{0};

  /// @throws OptionError naming the field, its value and the bound:
  /// num_axes in [1, kMaxQuadratureAxes] (two channel bits per axis of a
  /// 16-bit word), glitch_filter_samples in [0, 1000000] (the filter keeps
  /// one run counter per channel; a million samples is seconds of a
  /// capture at MHz rates, far past any glitch).
  void Validate() const;
};

/// Signed 4x count of every axis since the first sample (formats.md §8.2):
/// each edge of A or B counts one; (A,B) = 00 -> 10 -> 11 -> 01 -> 00 is +1
/// per step, the reverse -1. A sample where A and B of one axis both change is
/// an error event: the count is unchanged, the axis's error counter grows by
/// one and decoding continues from the new state.
///
/// The first sample ever decoded is the reference state (count 0). Decode()
/// may be called any number of times with consecutive blocks; the result does
/// not depend on how the capture is split.
class QuadratureDecoder {
 public:
  /// @throws OptionError for bad options (QuadratureOptions::Validate).
  explicit QuadratureDecoder(const QuadratureOptions& options = {});

  /// Decodes `n` consecutive samples.
  void Decode(const std::uint16_t* words, std::size_t n);
  void Decode(std::span<const std::uint16_t> words) { Decode(words.data(), words.size()); }

  /// Count of axis k after the last decoded sample.
  std::int64_t count(int axis) const { return counts_[axis]; }
  std::span<const std::int64_t> counts() const { return {counts_.data(), counts_.size()}; }
  /// Error events (both channels of one axis changed in one sample).
  std::span<const std::int64_t> error_events() const { return {errors_.data(), errors_.size()}; }
  /// Number of samples decoded so far.
  std::int64_t samples() const { return samples_; }
  int num_axes() const { return options_.num_axes; }

 private:
  void DecodeUnfiltered(const std::uint16_t* words, std::size_t n);
  void DecodeFiltered(const std::uint16_t* words, std::size_t n);
  void Transition(std::uint32_t from, std::uint32_t to);

  QuadratureOptions options_;
  std::uint32_t mask_{0};      // the 2 * num_axes channel bits
  std::uint32_t state_{0};     // current (filtered) level of every channel
  std::int64_t samples_{0};
  std::vector<std::int64_t> counts_;
  std::vector<std::int64_t> errors_;
  // Glitch filter: per channel bit, how many consecutive samples the raw level
  // has differed from state_.
  std::uint32_t pending_{0};
  std::vector<int> run_;
};

}  // namespace robomach::machine
