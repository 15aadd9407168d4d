#pragma once
// Compensation as a Siemens 840D sl applies it (seed 002, eqs. (2)-(5);
// formats.md §8.4): measuring-system tables, sag / cross-axis tables and
// temperature compensation, from measured to real axis positions and back.

#include <string>
#include <vector>

namespace robomach::machine {

/// An equidistant table: point i at min + i * step; linear between points,
/// the first / last value held outside [min, min + (n - 1) step]
/// [seed 002, eq. (4)]. SI: positions and values in m (linear) or rad (rotary).
struct CompensationTable {
  double min{0.0};
  double step{1.0};                 // > 0
  std::vector<double> values;       // at least 1 point

  double Evaluate(double position) const;
};

/// `$AA_ENC_COMP`: value added to the axis itself, input its own measured position.
struct EncoderCompensation {
  int axis{0};
  CompensationTable table;
};

/// `$AN_CEC` (sag / cross-axis): input the base axis's measured position,
/// value added to the compensated axis.
struct CrossAxisCompensation {
  int input_axis{0};
  int output_axis{0};
  CompensationTable table;
};

/// One row of the temperature log: dTemp = K0 + tan_beta (P - P0) [seed eq. (5)],
/// in force from t_s until the next row of the same axis.
struct TemperatureRow {
  double t_s{0.0};       // [s], on the counts file's clock
  double k0{0.0};        // [m]
  double tan_beta{0.0};  // [-]
  double p0{0.0};        // [m]
};

struct TemperatureCompensation {
  int axis{0};
  std::vector<TemperatureRow> rows;  // t_s strictly increasing
};

/// All compensation of one machine. Immutable after construction.
class Compensation {
 public:
  Compensation() = default;
  /// @throws std::invalid_argument for an axis index outside [0, num_axes),
  ///   an empty or non-finite table, step <= 0, or temperature rows not
  ///   strictly increasing in time.
  Compensation(int num_axes, std::vector<EncoderCompensation> encoder,
               std::vector<CrossAxisCompensation> cross_axis,
               std::vector<TemperatureCompensation> temperature);

  int num_axes() const { return num_axes_; }
  bool empty() const { return encoder_.empty() && cross_.empty() && temperature_.empty(); }

  /// Real = measured + dMeas(measured) + dTemp(t, measured) + sum of
  /// dSag(base axis measured) [seed eq. (3)]. Arrays of num_axes().
  void MeasuredToReal(double t_s, const double* measured, double* real) const;
  /// The inverse: the measured positions whose real positions are `real`
  /// (fixed-point iteration; the tables' slopes are far below 1).
  /// @throws std::runtime_error if it does not converge (slopes near 1).
  void RealToMeasured(double t_s, const double* real, double* measured) const;
  /// The total compensation value of every axis at these measured positions.
  void Offsets(double t_s, const double* measured, double* offset) const;

 private:
  int num_axes_{0};
  std::vector<EncoderCompensation> encoder_;
  std::vector<CrossAxisCompensation> cross_;
  std::vector<TemperatureCompensation> temperature_;
};

}  // namespace robomach::machine
