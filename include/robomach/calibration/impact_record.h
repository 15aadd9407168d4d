#pragma once

// The input of FRF estimation from impact tests (frf_estimate.h): the time
// records of one hit and what each response channel measures. Plain value
// types on Eigen only, so that the reader in `io` (io/hammer_records.h) can
// return them without depending on the estimator.

#include <string>

#include <Eigen/Core>

namespace robomach::calibration {

/// What a response transducer measures (SI): displacement [m], velocity
/// [m/s] or acceleration [m/s²]. The FRF of a channel is then receptance,
/// mobility or accelerance [per N].
enum class ResponseQuantity { kDisplacement, kVelocity, kAcceleration };

/// One response channel of the records.
struct ResponseChannel {
  std::string name;  // e.g. "acc_x" (the column without its unit suffix)
  ResponseQuantity quantity{ResponseQuantity::kAcceleration};
};

/// One hit: force and responses sampled together, evenly in time.
struct ImpactRecord {
  std::string id;            // hit id, as named in notes ("3", "hit_03")
  std::string source;        // where it came from, e.g. "hits.csv:2" (for notes)
  double start_time_s{0.0};  // time of the first sample [s]
  double sample_rate_hz{0.0};
  Eigen::VectorXd force_N;   // [N]
  Eigen::MatrixXd response;  // samples × channels, SI unit of each channel
};

}  // namespace robomach::calibration
