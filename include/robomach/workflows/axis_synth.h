#pragma once
// axis-synth as one library call (issue #36): a machine file (with its
// rotary errors), a programmed path and optionally the controller's
// compensation tables and temperature log -> the encoder counts a five-axis
// machine would record (formats.md §8.1), with the checks of the options
// and the inputs and the verdict. The tool parses its options into
// AxisSynthOptions and writes the counts, the raw quadrature capture
// behind them (formats.md §8.2, AxisSynthRun::Capture) and the machine file
// with the measured start as origins.

#include <map>
#include <string>
#include <vector>

#include "robomach/common/messages.h"
#include "robomach/common/option_checks.h"
#include "robomach/common/run_status.h"
#include "robomach/io/machine_file.h"
#include "robomach/machine/synthesis.h"

namespace robomach::workflows {

/// axis-synth's options (the tool's option for each field: machine_path is
/// --machine, program_path --program, compensation_path --compensation,
/// temperature_path --temperature, origins_at_start --machine-out, ...).
struct AxisSynthOptions : FieldNames {
  std::string machine_path;       // machine file YAML (formats.md §8.3)
  std::string program_path;       // programmed path CSV x_mm,y_mm,z_mm,i,j,k (workpiece coordinates)
  std::string compensation_path;  // Siemens 840D sl tables (formats.md §8.4) the controller applies; empty: none
  std::string temperature_path;   // temperature log t_s,axis,K0_mm,tan_beta,P0_mm; empty: none
  double feed_mm_min{2000.0};     // tool tip speed along the path [mm/min]
  double sample_rate_hz{8000.0};  // counts rows per second [Hz]
  double dwell_s{0.0};            // time at the first point before moving [s]
  double start_b_deg{-90.0};      // B near which the first point's inverse kinematics is chosen [deg]
  /// The machine's origins become the measured start position, so that the
  /// first counts row is the reference; otherwise the machine file's origins
  /// must be that position.
  bool origins_at_start{false};
  long max_rows{1000000};  // a longer record is refused before it is computed (about 45 bytes a row)
  /// The raw capture (Capture): samples per counts row, the last samples of
  /// each row interval without an edge, the chance per sample of a glitch
  /// on an idle axis, and the seed of its start phases and glitches.
  int capture_every{10};
  int capture_settle{2};
  double glitch_probability{0.0};
  unsigned seed{1};
  // names, Name(field): how the findings and messages name the fields
  // (FieldNames; the tool: its options, "--feed-mm-min").

  /// The options alone, before any file is read.
  /// @throws OptionError naming the field: feed_mm_min outside [1e-3, 1e6],
  ///   sample_rate_hz outside [1, 1e8], dwell_s outside [0, 1e5],
  ///   start_b_deg outside [-720, 720], glitch_probability outside [0, 1],
  ///   max_rows outside [2, 1e9], capture_every outside [1, 100000],
  ///   capture_settle outside [0, capture_every).
  void Validate() const;
  /// The options that look like a unit mistake (docs/plausibility.md): the
  /// feed, the sample rate, the dwell, and start_b_deg in radians or beyond
  /// a turn. RunAxisSynth puts them in its unit_findings without telling
  /// them: a caller that checks its files first tells them before that.
  std::vector<std::string> UnitFindings() const;
};

struct AxisSynthRun {
  io::MachineFile machine;  // as read; with origins_at_start, the measured start as origins
  machine::CountsRecord record;  // the counts; the first row is all zero (the reference)
  /// The options' unit findings (UnitFindings), then the machine file's,
  /// the compensation tables' and the temperature log's (each told as a
  /// warning).
  std::vector<std::string> unit_findings;

  bool flagged() const { return !unit_findings.empty(); }
  RunStatus status() const { return flagged() ? RunStatus::kFlagged : RunStatus::kOk; }
  /// The synthesizer of the raw capture behind the counts (the options'
  /// capture_every, capture_settle, glitch_probability and seed).
  machine::CaptureSynthesizer Capture(const AxisSynthOptions& options) const;
  /// Writes the raw capture behind the counts (formats.md §8.2: 16-bit
  /// little-endian words, one per capture sample) to `path`, complete or not
  /// at all, and returns its sample and glitch counts.
  /// @throws OptionError("capture_every", "capture_every N: ...; raise
  ///   capture_every or lower feed_mm_min") when a move is too fast for the
  ///   capture rate (an edge per sample at most).
  struct CaptureCounts {
    long samples{0};
    long glitches{0};
  };
  CaptureCounts WriteCapture(const AxisSynthOptions& options, const std::string& path) const;
  /// Writes the counts (formats.md §8.1) with axis-synth's header: the
  /// generator, the machine file the counts are measured from (machine_out
  /// when the machine file with the start as origins is written, else the
  /// options' machine_path), the program and the sample rate.
  void WriteCounts(const AxisSynthOptions& options, const std::string& path, const std::string& machine_out) const;
};

/// Reads the machine file, the path, the compensation tables and the
/// temperature log (their unit findings are warnings), refuses a record of
/// more than max_rows, and synthesizes the counts.
/// @throws OptionError naming the field (Validate; feed_mm_min when the
///   record is longer than max_rows); InputError for the files, a path the
///   machine cannot follow (program_path) and a start that is not the
///   origins (machine_path).
AxisSynthRun RunAxisSynth(const AxisSynthOptions& options, const MessageSink& tell = {});

}  // namespace robomach::workflows
