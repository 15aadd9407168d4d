#pragma once

// FRFs in Universal File Format dataset 58 (formats.md §4): io/uff58.h reads
// the records, this maps them to FRFs (directions, units, quantity).

#include <ostream>
#include <string>

#include "robomach/io/frf_quantity.h"

namespace robomach::io {

/// Reads the FRFs of a Universal File Format file as modal-analysis
/// software and acquisition systems export it (io/uff58.h reads the
/// records: ASCII 58 and binary 58b, dataset 164 units; other datasets are
/// skipped and named in a note).
///
/// - Function type 4 records are FRFs (complex ordinates); function type 6
///   (coherence, real) is attached to the FRF with the same response and
///   reference node and direction. Every other function (time response,
///   spectrum, ...) is skipped with a note naming it; a file with no FRF at
///   all is an error that says what it holds.
/// - Directions: record 6 codes 1/-1 = x, 2/-2 = y, 3/-3 = z; a negative
///   code (or a '-' in the entity name) means the transducer points along
///   -axis, so the value is negated once per negative end. Code 0 (scalar):
///   the direction is read from the entity name (".1.Z-", "12:+X"); with
///   none, the FRF is read as a direct FRF xx with a warning (a symmetric
///   tool, as a tap test on one axis gives). Rotational codes are errors.
/// - Quantity and units: the ordinate's specific data type (record 9: 8
///   displacement, 11 velocity, 12 acceleration), else the unit labels of
///   records 9 and 10 ("(m/s)/N", "g/lbf", "mm/s^2" over "N" ...; see
///   ParseUnitLabel), else the axis label's word ("Mobility", "Inertance"
///   ...) with a warning, else receptance with a warning. A code and a label
///   that disagree are an error. Values are converted to SI by the labels'
///   factors, or, for unlabelled axes, by dataset 164's factors with the
///   records' length and force exponents; labels that disagree with 164
///   are an error. Mobility and accelerance are converted to receptance
///   (the 0 Hz line, which has no receptance, is dropped).
/// - The abscissa is frequency in Hz (a label "rad/s" or "kHz" is converted);
///   time, rpm and order abscissae are errors for an FRF.
/// - The posture is `pose=ID` in ID line 1 of the record; otherwise
///   `default_pose_id` (from `--pose ID=file.uff`); otherwise the FRF has no
///   posture (empty pose id): a tool that needs one says so.
/// - Two FRF records of the same posture and directions (other nodes) are
///   an error: a file holds the FRFs of one tool-tip point per posture.
/// @throws InputError "file:line[:col]: ..." naming the record and field.
FrfReadResult ReadUff58(const std::string& path, const std::string& default_pose_id = "", bool keep_points = false);

/// Writes one dataset 58 record per FRF (complex double, format 4E20.12;
/// even spacing when the grid is even, else E13.5,2E20.12), `pose=ID` in
/// ID line 1, and a coherence record (function type 6) per FRF that has
/// coherence. Atomic. The abscissa is written in E13.5 as the format
/// prescribes; this keeps 6 significant digits of f_min and Δf.
void WriteUff58(const std::string& path, const dynamics::FrfSet& frfs,
                FrfQuantity quantity = FrfQuantity::kReceptance);
void WriteUff58(std::ostream& os, const dynamics::FrfSet& frfs,
                FrfQuantity quantity = FrfQuantity::kReceptance);

/// Rounds to 13 significant digits, the precision of UFF58's E20.12 field.
/// Data rounded so carry identical values in a CSV and a UFF58 copy.
double RoundToUffPrecision(double v);

}  // namespace robomach::io
