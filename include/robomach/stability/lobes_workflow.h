#pragma once
// stability-lobes' workflow as one library call (issue #21): the ZOA and/or
// the semi-discretization lobes of a set of tool tips (tip_dynamics.h), the
// checks of the tips' modal fits, and the comparison of the two methods.

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "robomach/common/run_status.h"
#include "robomach/stability/milling.h"
#include "robomach/stability/semi_discretization.h"
#include "robomach/stability/tip_dynamics.h"
#include "robomach/stability/zoa_lobes.h"

namespace robomach::stability {

enum class LobeMethod { kZoa, kSd, kBoth };
/// "zoa", "sd", "both" (stability-lobes --method).
const char* ToString(LobeMethod m);
/// The inverse of ToString.
/// @throws OptionError (field method) naming the accepted names.
LobeMethod ParseLobeMethod(const std::string& name);

/// One point of the lobes of one tool tip by one method.
struct LobeRow {
  std::string id;      // the tool tip's id
  std::string method;  // "zoa" or "sd"
  LobePoint point;
  /// With parameter uncertainty (ZoaLobeBand): the critical depth's
  /// interval [m]; NaN otherwise.
  double depth_lower{NAN}, depth_upper{NAN};
};

struct LobesOptions {
  LobeMethod method{LobeMethod::kZoa};
  MillingProcess process;
  double min_speed_rad_s{0.0};  // the cut's speed range: the ZOA's lowest lobe, the
  double max_speed_rad_s{0.0};  // ZOA-SD comparison's search window
  Eigen::VectorXd zoa_speeds_rad_s;  // where the ZOA lobes are sampled
  Eigen::VectorXd sd_speeds_rad_s;   // where the SD is solved
  int max_lobe_index{30};            // ZoaOptions::max_lobe_index
  SdOptions sd;
  int sd_modes{3};  // stability-lobes' default: dominant modes of a model (not fitted) tip the SD keeps
  int threads{0};   // SD threads (0 = all cores)

  /// @throws OptionError naming the field, its value and the bound:
  /// min_speed_rad_s >= 0 and max_speed_rad_s >= min_speed_rad_s (the cut's
  /// range), with the SD every sd_speeds_rad_s finite > 0 (its tooth period
  /// 2π/(NΩ)), max_lobe_index >= 0, sd_modes >= 1, threads >= 0, and the
  /// nested sd.* fields (SdOptions::Validate, field prefixed). The process
  /// is checked by MillingProcess::Validate (std::invalid_argument).
  /// stability-lobes and Python check their own options first
  /// (workflows::StabilityLobesOptions::ValidateSettings, narrower ranges).
  void Validate() const;
};

/// What the run has to say as it goes (kInfo: the SD's discretisation), and
/// the SD's progress per tool tip: `done` of `total`
/// speeds; `finished` once, after the last.
struct SdProgress {
  std::string id;
  long done{0}, total{0};
  bool finished{false};
};
using SdProgressSink = std::function<void(const SdProgress&)>;

/// The SD's discretisation of one tip, as ComputeLobes tells it before the
/// work: the modes kept, the highest of them, and the steps per tooth
/// period over the speeds (SdStepsPerPeriod).
struct SdDiscretisation {
  std::string id;
  int modes{0};
  double highest_mode_hz{NAN};                          // [Hz]
  int min_steps_per_period{0}, max_steps_per_period{0};
  bool capped{false};  // automatic steps capped by SdOptions::max_monodromy_dimension at some speed
};

/// The comparison of the two methods' smallest critical depths for one tip
/// (both methods, radial immersion 0.3 or more). The SD's minimum is over
/// its speeds and the extra speeds near the ZOA's lobe bottoms, which are in
/// no lobes row: this is where that number is kept.
struct ZoaSdComparison {
  std::string id;
  double sd_min_depth{NAN}, sd_min_depth_speed_rad_s{NAN};    // [m], [rad/s]
  double zoa_min_depth{NAN}, zoa_min_depth_speed_rad_s{NAN};  // [m], [rad/s]
  double relative_difference{NAN};  // |SD − ZOA| / min(SD, ZOA)
  bool agree{true};                 // relative_difference <= 0.10
};

/// A measured tip's ZOA on its measured FRF against the ZOA on the modes
/// fitted to it (TipDynamics::fit_C, on the model grid): the smallest
/// critical depths over the ZOA's speeds. They differ when the fit misses
/// what the lines show (a mode left out, a poor fit) or the lines miss what
/// the fit shows (a resonance narrower than the line spacing).
struct ZoaFitCheck {
  std::string id;
  double measured_min_depth{NAN}, fit_min_depth{NAN};  // [m]
  double relative_difference{NAN};                     // |measured − fit| / min of the two
  bool agree{true};                                    // relative_difference <= 0.10
};

/// Flagged (its `verdict`; stability-lobes' exit 3), one finding each, for a
/// modal fit that does not describe a tool tip (TipFitWarnings: an
/// implausible unit, not a driving point, a mode at the edge of the usable
/// band, a poor fit, no mode for the SD), the ZOA and the SD more than 10 %
/// apart where they should agree, and speeds without a boundary. Each
/// finding is also told to the message sink as a warning when it is found.
struct LobesResult {
  RunFindings verdict;
  RunStatus status() const { return verdict.status(); }
  std::vector<LobeRow> rows;  // per tip: the ZOA's rows, then the SD's
  /// Some speeds have no boundary (a ZOA point that is not ok, an SD point
  /// unstable at depth zero).
  bool no_boundary{false};
  std::vector<SdDiscretisation> sd_discretisation;  // per tip the SD was run on
  std::vector<ZoaSdComparison> comparisons;         // per tip compared (see ComputeLobes)
  std::vector<ZoaFitCheck> zoa_fit_checks;          // per measured tip with the ZOA
};

/// The warnings about one tip's measured FRFs (empty for a model tip): its
/// unit finding, then one per problem of its modal fits, each naming the
/// FRF. `sd` adds "no mode, no SD lobes".
std::vector<std::string> TipFitWarnings(const TipDynamics& tip, bool sd);

/// The lobes of every tip: the ZOA on its FRF (ComputeZoaLobes sampled at
/// zoa_speeds_rad_s), the SD on its modes (SdLobes at sd_speeds_rad_s; a
/// model tip keeps its sd_modes dominant modes, a fitted one what the fit
/// kept). With both methods at a radial immersion of 0.3 or more the
/// smallest critical depths must agree within 10 %: the SD's minimum is
/// also searched on 7 speeds within ±4 % of the bottom of each of the (at
/// most 4) lowest ZOA lobes. A measured tip's ZOA is checked against the
/// ZOA on its fitted modes (ZoaFitCheck; flagged beyond 10 %).
/// @throws OptionError for bad options (LobesOptions::Validate).
LobesResult ComputeLobes(const std::vector<TipDynamics>& tips, const LobesOptions& options,
                         const MessageSink& on_message = {}, const SdProgressSink& on_progress = {});

/// The lobes of one tip by one method in a few numbers (stability-lobes'
/// summary): the speeds, those with a boundary, and the smallest and
/// largest critical depth with their speeds.
struct LobeSummary {
  std::string id, method;
  int speeds{0}, speeds_with_boundary{0};
  double min_depth{NAN}, min_depth_speed_rad_s{NAN}, min_depth_chatter_freq_hz{NAN};  // [m], [rad/s], [Hz]
  double max_depth{NAN}, max_depth_speed_rad_s{NAN};
};

/// One summary per tip and method that has rows, in the tips' order, the
/// ZOA before the SD.
std::vector<LobeSummary> SummarizeLobes(const std::vector<TipDynamics>& tips, const std::vector<LobeRow>& rows);

}  // namespace robomach::stability
