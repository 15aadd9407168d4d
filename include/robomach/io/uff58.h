#pragma once

// Universal File Format (UFF) as modal-analysis software and data
// acquisition systems export it: the records of dataset 58 ("function at
// nodal DOF", ASCII) and 58b (its binary form), the unit system of dataset
// 164, and every other dataset skipped by number. This is the raw level: the
// records as stored, with their header fields; io/frf_files.h turns the FRF
// records among them into tool-tip receptances.
//
// - [SDRC 1993] Structural Dynamics Research Corporation, I-DEAS Universal
//   File Format, datasets 58 "Function at Nodal DOF" (records 1-12), 58b
//   (binary variant: the 58b header line gives byte order, floating-point
//   format, the number of ASCII header lines and of data bytes) and 164
//   "Units" (factors "for converting universal file units to SI: to convert
//   from universal file units to SI divide by the appropriate factor").

#include <map>
#include <optional>
#include <string>
#include <vector>

#include <Eigen/Core>

namespace robomach::io {

/// What record 6 field 1 of dataset 58 says the function is, in words:
/// 1 "time response", 4 "frequency response function", 6 "coherence",
/// 12 "spectrum", ... ; "function type N (unknown)" for codes outside the
/// table of [SDRC 1993].
std::string UffFunctionTypeName(int code);

/// The physical dimension of a unit label such as "(m/s)/N", "mm/s^2",
/// "g", "(1/N)*(m/s²)", "lbf": SI value = factor × value in the label's unit,
/// with the dimension L^length F^force T^time (length in m, force in N,
/// time in s). An empty label, "NONE" and "none" are `given` = false.
struct UnitDimension {
  bool given{false};
  double factor{1.0};
  int length{0}, force{0}, time{0};
  bool operator==(const UnitDimension& o) const {
    return length == o.length && force == o.force && time == o.time;
  }
};

/// Parses a unit label: products and quotients (`*`, `/`, `.`, a space) of
/// units with exponents (`^2`, `**2`, `2`, `²`, `³` in UTF-8 or Latin-1,
/// `^-1`) and parentheses. Units: m, cm, mm, um, µm, μm, in, inch, ft, N,
/// kN, mN, lbf, lb (pound-force), kgf, g and gn (standard gravity,
/// 9.80665 m/s²), s, sec, ms, min, Hz, kHz, rad, 1.
/// @throws std::invalid_argument naming the part it cannot convert, e.g.
///   "unit 'V' (in \"V/N\") is not a mechanical unit robomach can convert".
UnitDimension ParseUnitLabel(const std::string& label);

/// One axis of a dataset 58 record (records 8-11: format I10,3I5,2(1X,20A1)).
struct UffAxis {
  int specific_type{0};   // 8 displacement, 11 velocity, 12 acceleration, 13 excitation force, 17 time, 18 frequency...
  int length_exponent{0}, force_exponent{0}, temperature_exponent{0};
  std::string label;      // axis label, trimmed
  std::string units;      // units label, trimmed
  int line{0};
};

/// One dataset 58 or 58b record, as stored.
struct Uff58Record {
  int line{0};            // line of the "58"/"58b" dataset number (1-based)
  bool binary{false};
  std::string id_lines[5];  // records 1-5, right-trimmed
  int function_type{0};
  int function_id{0}, version{0}, load_case{0};
  std::string response_entity;  // record 6, 10A1, trimmed
  int response_node{0}, response_direction{0};
  std::string reference_entity;
  int reference_node{0}, reference_direction{0};
  int record6_line{0};
  int ordinate_type{0};   // 2 real single, 4 real double, 5 complex single, 6 complex double
  long num_points{0};
  bool even{true};
  double x_min{0.0}, dx{0.0};
  int record7_line{0};
  UffAxis abscissa, ordinate, denominator, z_axis;
  Eigen::VectorXd x;      // abscissa as stored (even grids expanded)
  Eigen::VectorXcd y;     // ordinates as stored (imaginary part 0 when real)
  bool complex() const { return ordinate_type == 5 || ordinate_type == 6; }
  /// Values after the announced num_points in the data block (ignored), and
  /// whether all of them were zero.
  long trailing_values{0};
  bool trailing_all_zero{true};
};

/// Dataset 164: the unit system of the records that follow it.
struct UffUnits {
  int code{1};
  std::string description;
  /// Factors of [SDRC 1993]: a length in file units divided by `length`
  /// is in m, a force divided by `force` is in N.
  double length{1.0}, force{1.0};
  int line{0};
};

struct UffFile {
  std::vector<Uff58Record> records;  // datasets 58 and 58b, in file order
  /// The 164 dataset in force for each record (index into `units`), or -1.
  std::vector<int> record_units;
  std::vector<UffUnits> units;
  /// Other datasets, skipped: dataset number -> lines where they start.
  std::map<std::string, std::vector<int>> skipped;
};

/// Reads every dataset of a UFF file (ASCII and 58b binary records may be
/// mixed, CR-LF or LF line ends). Data lines are read as free-format
/// numbers, also when fields touch ("-3.09944E-004-2.74181E-004") or use a
/// Fortran D exponent; reading stops at record 7's point count (exports
/// often pad the last line with zeros). Binary blocks are read exactly as
/// the 58b header declares: byte order 1 (little endian) or 2 (big endian),
/// IEEE floating point (format 2), the declared number of ASCII header lines
/// and data bytes; an uneven abscissa is 4-byte (it is E13.5 in ASCII) unless
/// the byte count says 8.
/// @throws InputError (path:line[:column]) for a malformed record, naming
///   the record and field and what was expected.
UffFile ReadUffFile(const std::string& path);

/// True if the file starts (after blank lines) with the UFF delimiter "-1".
bool LooksLikeUff(const std::string& path);

}  // namespace robomach::io
