#pragma once
// What a machine with given errors and tables would record for a programmed
// path (axis-synth): encoder counts, and the raw quadrature capture behind
// them. For rehearsal and for tests, as frf-synth is for hammer tests.

#include <cstdint>
#include <random>
#include <string>
#include <vector>

#include "robomach/machine/acquisition.h"

namespace robomach::machine {

struct SynthesisOptions {
  double feed{2000.0 / 60000.0};  // tool tip speed along the path [m/s]
  double sample_rate_hz{8000.0};  // counts rows per second
  double dwell{0.0};              // time at the start point before moving [s]
  /// Where the first sample's inverse kinematics starts looking (kinematic
  /// axis order, SI); empty = all zero. Picks the B solution of the first point.
  std::vector<double> initial_guess;

  /// @throws OptionError naming the field, its value and the bound: feed
  /// finite > 0 and sample_rate_hz finite > 0 (the rows are (dwell +
  /// length / feed) · rate), dwell finite >= 0. initial_guess's size is
  /// checked against the machine by SynthesizeCounts.
  void Validate() const;
};

struct CountsRecord {
  std::vector<double> t_s;
  std::vector<std::int64_t> counts;  // row-major, rows x num_axes
  int num_axes{0};
  long rows() const { return static_cast<long>(t_s.size()); }
};

struct SynthesisResult {
  CountsRecord record;
  std::vector<double> start_measured;  // measured axis positions at t = 0 [m, rad]
  bool ok{true};
  std::string message;                 // why not, naming the sample and point
};

/// The machine follows the path at the feed with the true kinematics
/// (errors included); the controller's compensation is then undone
/// (real -> measured) and the measured positions are quantised to counts
/// relative to `origin` (one value per axis: counts = round((measured -
/// origin) / resolution)). Pass start_measured of a first call, or the
/// machine file's origins. Axes the kinematics does not use stay at origin.
/// @throws OptionError for bad options (SynthesisOptions::Validate).
SynthesisResult SynthesizeCounts(const Machine& machine, const Compensation* compensation,
                                 const ProgrammedPath& path, const SynthesisOptions& options,
                                 const std::vector<double>& origin);

/// The rows SynthesizeCounts writes: ceil((dwell + length / feed) * rate) + 1
/// (LONG_MAX when that is beyond a long).
/// @throws OptionError for bad options (SynthesisOptions::Validate).
long SynthesisRows(const ProgrammedPath& path, const SynthesisOptions& options);

/// Measured start positions only (the first sample of SynthesizeCounts).
std::vector<double> StartMeasured(const Machine& machine, const Compensation* compensation,
                                  const ProgrammedPath& path, const SynthesisOptions& options);

/// Writes a raw capture (formats.md §8.2) for consecutive count rows: between
/// two rows `every` capture samples; each axis's steps are spread evenly over
/// the first `every - settle` of them, so that a glitch filter of up to
/// settle + 1 samples still shows every step by the row's sample. Optional
/// single-sample glitches on one channel, placed only where
/// that axis is idle on both neighbouring samples, so a glitch filter of 2
/// samples removes them all.
class CaptureSynthesizer {
 public:
  CaptureSynthesizer(int num_axes, int every, int settle, double glitch_probability, unsigned seed,
                     std::vector<std::string> axis_names = {});
  /// Words for the first row (one sample).
  void Start(const std::int64_t* counts, std::vector<std::uint16_t>* out);
  /// Words for the `every` samples that lead from the previous row to `counts`.
  /// @throws std::invalid_argument if an axis moves more than `every` counts.
  void Next(const std::int64_t* counts, std::vector<std::uint16_t>* out);
  long glitches() const { return glitches_; }

 private:
  std::uint16_t Word(const std::int64_t* c) const;
  int num_axes_, every_, settle_;
  std::vector<int> phase0_;
  std::vector<std::string> names_;
  double glitch_probability_;
  std::mt19937 rng_;
  std::vector<std::int64_t> current_;
  long glitches_{0};
  long rows_{0};
};

}  // namespace robomach::machine
