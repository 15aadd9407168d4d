#include "robomach/io/frf_uff58.h"

#include <algorithm>
#include <cctype>
#include <charconv>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <regex>
#include <sstream>

#include "robomach/common/errors.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/uff58.h"
#include "frf_text.h"

#include "text.h"

namespace robomach::io {

using dynamics::Frf;
using dynamics::FrfKey;
using dynamics::FrfSet;
using frf_text::CheckLowFrequencyTrend;
using frf_text::Fmt;
using frf_text::Pad80;
using frf_text::PadTo;
using frf_text::Printf;

namespace {

struct Direction {
  bool known{false};
  Axis axis{Axis::kX};
  int sign{1};
  int node{0};           // from the entity name, when it has one
  bool from_name{false};
};

// The direction of one end of a record: record 6's code, or, when that is 0
// (a scalar DOF), the entity name as test software writes it: ".1.Z-",
// "1:+X", "12Y-", "Pt3-Z".
Direction RecordDirection(const std::string& path, int line, int column, int code, const std::string& entity,
                          const std::string& which) {
  Direction d;
  static const std::regex name_re(R"(^(.*?)([+-]?)([XYZxyz])([+-]?)$)");
  static const std::regex node_re(R"((\d+)\D*$)");
  std::smatch m;
  const bool name_has_axis = std::regex_match(entity, m, name_re) &&
                             (m[1].str().empty() || !std::isalpha(static_cast<unsigned char>(m[1].str().back())));
  if (name_has_axis) {
    std::smatch n;
    const std::string head = m[1].str();
    // Not std::stoi: ten digits fit record 6's entity name and overflow an
    // int (std::out_of_range; issue #22).
    if (std::regex_search(head, n, node_re)) {
      const std::string digits = n[1].str();
      if (std::from_chars(digits.data(), digits.data() + digits.size(), d.node).ec != std::errc()) {
        throw InputError({path, line, column}, "record 6: " + which + " entity name \"" + entity + "\": node number " +
                                                   digits + " is out of range (at most 2147483647)");
      }
    }
  }
  const int a = std::abs(code);
  if (a >= 1 && a <= 3) {
    d.known = true;
    d.axis = static_cast<Axis>(a - 1);
    d.sign = code < 0 ? -1 : 1;
    return d;
  }
  if (a >= 4 && a <= 6) {
    throw InputError({path, line, column},
                     "record 6: " + which + " direction " + std::to_string(code) +
                         " is rotational; robomach reads translational tool-tip FRFs (codes 1/-1 x, 2/-2 y, 3/-3 z)");
  }
  if (code != 0) {
    throw InputError({path, line, column}, "record 6: " + which + " direction " + std::to_string(code) +
                                               " is not a UFF direction code (0 scalar, 1-3 translational, 4-6 "
                                               "rotational, negative for -axis)");
  }
  if (name_has_axis) {
    d.known = true;
    d.from_name = true;
    d.axis = ParseAxis(m[3].str());
    d.sign = (m[2].str() == "-") != (m[4].str() == "-") ? -1 : 1;
  }
  return d;
}

// The quantity of an FRF's ordinate from the record's axis label word.
std::optional<FrfQuantity> QuantityFromWord(const std::string& label) {
  const std::string l = Lower(label);
  if (l.find("receptance") != std::string::npos || l.find("compliance") != std::string::npos) {
    return FrfQuantity::kReceptance;
  }
  if (l.find("mobility") != std::string::npos || l.find("admittance") != std::string::npos) {
    return FrfQuantity::kMobility;
  }
  if (l.find("accelerance") != std::string::npos || l.find("inertance") != std::string::npos) {
    return FrfQuantity::kAccelerance;
  }
  return std::nullopt;
}

std::string UnitOf(FrfQuantity q) {
  switch (q) {
    case FrfQuantity::kReceptance: return "m/N";
    case FrfQuantity::kMobility: return "(m/s)/N";
    case FrfQuantity::kAccelerance: return "(m/s^2)/N";
  }
  return "?";
}

UnitDimension ParseLabelAt(const std::string& path, const UffAxis& a, const std::string& record) {
  return AtLocation({path, a.line, 48}, record + " units label: ", [&] { return ParseUnitLabel(a.units); });
}

struct RecordUnits {
  FrfQuantity quantity{FrfQuantity::kReceptance};
  double factor{1.0};  // SI ordinate = factor × stored ordinate
};

// The quantity and SI factor of an FRF record (records 9 and 10, the unit
// labels, dataset 164), with notes for what was inferred.
RecordUnits FrfRecordUnits(const std::string& path, const Uff58Record& r, const UffUnits* units,
                           std::vector<std::string>* notes, std::vector<std::string>* warnings) {
  const std::string at = path + ":" + std::to_string(r.ordinate.line);
  // 1. The specific data types.
  std::optional<FrfQuantity> by_code;
  switch (r.ordinate.specific_type) {
    case 8: by_code = FrfQuantity::kReceptance; break;
    case 11: by_code = FrfQuantity::kMobility; break;
    case 12: by_code = FrfQuantity::kAccelerance; break;
    case 0: case 1: break;
    default:
      throw InputError({path, r.ordinate.line, 1},
                       "record 9: ordinate specific data type " + std::to_string(r.ordinate.specific_type) +
                           " is not 8 (displacement), 11 (velocity) or 12 (acceleration), so this FRF is not a "
                           "receptance, mobility or accelerance");
  }
  const int den = r.denominator.specific_type;
  if (den != 0 && den != 1 && den != 9 && den != 13) {
    throw InputError({path, r.denominator.line, 1},
                     "record 10: denominator specific data type " + std::to_string(den) +
                         " is not a force (13 excitation force, 9 reaction force) or 0 (unknown)");
  }
  // 2. The unit labels.
  const UnitDimension nu = ParseLabelAt(path, r.ordinate, "record 9");
  UnitDimension de = ParseLabelAt(path, r.denominator, "record 10");
  std::optional<FrfQuantity> by_unit;
  double label_factor = 1.0;
  if (nu.given || de.given) {
    UnitDimension q = nu;
    if (de.given) {
      q.factor /= de.factor;
      q.length -= de.length;
      q.force -= de.force;
      q.time -= de.time;
    } else if (nu.force == 0) {
      // "m/s^2" over an unlabelled force: the excitation in N.
      q.force -= 1;
      notes->push_back(at + ": record 10 gives no unit; the excitation force is taken in N");
    }
    const std::string shown = (nu.given ? r.ordinate.units : std::string("1")) +
                              (de.given ? " per " + r.denominator.units : std::string());
    if (q.length == 1 && q.force == -1 && q.time == 0) by_unit = FrfQuantity::kReceptance;
    else if (q.length == 1 && q.force == -1 && q.time == -1) by_unit = FrfQuantity::kMobility;
    else if (q.length == 1 && q.force == -1 && q.time == -2) by_unit = FrfQuantity::kAccelerance;
    else {
      throw InputError({path, r.ordinate.line, 48},
                       "record 9-10 units \"" + shown + "\" are m^" + std::to_string(q.length) + " N^" +
                           std::to_string(q.force) + " s^" + std::to_string(q.time) +
                           ", not a receptance (m/N), mobility ((m/s)/N) or accelerance ((m/s^2)/N)");
    }
    label_factor = q.factor;
  }
  // 3. Dataset 164 with the records' exponents.
  double f164 = 1.0;
  const bool exponents = r.ordinate.length_exponent || r.ordinate.force_exponent || r.denominator.length_exponent ||
                         r.denominator.force_exponent;
  if (units && exponents) {
    f164 = std::pow(units->length, -r.ordinate.length_exponent) * std::pow(units->force, -r.ordinate.force_exponent) *
           std::pow(units->length, r.denominator.length_exponent) * std::pow(units->force, r.denominator.force_exponent);
  }
  if (by_code && by_unit && *by_code != *by_unit) {
    throw InputError({path, r.ordinate.line, 1},
                     "record 9 says " + ToString(*by_code) + " (specific data type " +
                         std::to_string(r.ordinate.specific_type) + ") but the unit labels say " +
                         ToString(*by_unit) + " (" + UnitOf(*by_unit) + "); correct one of them in the export");
  }
  RecordUnits out;
  if (by_unit && units && exponents && std::abs(f164 / label_factor - 1.0) > 1e-6) {
    std::ostringstream m;
    m << "the unit labels (\"" << r.ordinate.units << "\" per \"" << r.denominator.units << "\", factor "
      << label_factor << " to SI) and dataset 164 at line " << units->line << " (" << units->description
      << ", factor " << f164 << " with the exponents of records 9-10) disagree; correct the export";
    throw InputError({path, r.ordinate.line, 48}, m.str());
  }
  out.factor = by_unit ? label_factor : f164;
  const std::optional<FrfQuantity> by_word = QuantityFromWord(r.ordinate.label);
  if (by_code || by_unit) {
    out.quantity = by_unit ? *by_unit : *by_code;
    const bool word_differs = by_word && *by_word != out.quantity;
    if (!by_code || word_differs) {
      std::string n = at + ": ";
      if (!by_code) {
        n += "record 9 gives no physical ordinate type (" + std::to_string(r.ordinate.specific_type) + "); ";
      }
      n += "its unit " + (by_unit ? r.ordinate.units + (de.given ? " per " + r.denominator.units : "")
                                  : std::string("(specific data type)")) +
           " makes it " + QuantityWithArticle(out.quantity);
      if (word_differs) n += ", although its axis label says \"" + r.ordinate.label + "\"";
      notes->push_back(n + "; read as " + ToString(out.quantity));
    }
  } else if (by_word) {
    out.quantity = *by_word;
    warnings->push_back(at + ": record 9 gives neither a physical ordinate type nor a unit; read as " +
                        ToString(out.quantity) + " [" + UnitOf(out.quantity) + "] from its axis label \"" +
                        r.ordinate.label + "\", in SI units");
  } else {
    out.quantity = FrfQuantity::kReceptance;
    warnings->push_back(at + ": record 9 gives no physical ordinate type (" +
                        std::to_string(r.ordinate.specific_type) + ") and no unit; read as receptance [m/N]");
  }
  return out;
}

// Hz per stored abscissa unit.
double AbscissaToHz(const std::string& path, const Uff58Record& r) {
  const int spec = r.abscissa.specific_type;
  if (spec == 17) {
    throw InputError({path, r.abscissa.line, 1}, "record 8: the abscissa is time (specific data type 17), but a " +
                                                     UffFunctionTypeName(r.function_type) +
                                                     " is a function of frequency");
  }
  if (spec != 0 && spec != 1 && spec != 18) {
    throw InputError({path, r.abscissa.line, 1},
                     "record 8: abscissa specific data type " + std::to_string(spec) +
                         (spec == 19 ? " (rpm)" : spec == 20 ? " (order)" : "") + " is not frequency (18)");
  }
  const std::string u = Lower(r.abscissa.units);
  if (u.find("rad") != std::string::npos) {
    const UnitDimension d = ParseLabelAt(path, r.abscissa, "record 8");
    if (d.time != -1 || d.length || d.force) {
      throw InputError({path, r.abscissa.line, 48}, "record 8: abscissa unit \"" + r.abscissa.units + "\" is not a frequency");
    }
    return d.factor / (2.0 * M_PI);
  }
  const UnitDimension d = ParseLabelAt(path, r.abscissa, "record 8");
  if (!d.given) return 1.0;
  if (d.time != -1 || d.length || d.force) {
    throw InputError({path, r.abscissa.line, 48}, "record 8: abscissa unit \"" + r.abscissa.units + "\" is not a frequency");
  }
  return d.factor;
}

struct FrfRecord {
  FrfKey key;
  int resp_node{0}, ref_node{0};
  int line{0};
};

std::string NodeText(int resp_node, Axis ra, int ref_node, Axis ea) {
  return "response " + std::to_string(resp_node) + AxisName(ra) + ", reference " + std::to_string(ref_node) +
         AxisName(ea);
}

// A coherence record kept until all records are read: it is attached to the
// FRF of the same nodes and directions, which may come later in the file.
struct Coherence {
  const Uff58Record* r;
  std::string pose;
  int resp_node, ref_node;
  Axis ra, ea;
};

// What is read of an FRF or coherence record before its ordinates: the
// directions and nodes of record 6, the posture and the abscissa scale.
struct RecordHead {
  Direction rd, ed;
  Axis ra{Axis::kX}, ea{Axis::kX};
  int resp_node{0}, ref_node{0};
  double hz{1.0};    // Hz per stored abscissa unit
  std::string pose;  // pose=ID of ID line 1, else the default
  std::string where; // "path:line" of the record, for notes
};

// Reads the records of one UFF file into `out`, stage by stage; the members
// are what the stages hand each other (the FRFs read so far, coherence
// records waiting for their FRF, records that are not FRFs).
struct Uff58Reader {
  const std::string& path;
  const UffFile& file;
  FrfReadResult& out;
  bool quantity_set = false;
  std::vector<FrfRecord> frf_records{};
  std::vector<Coherence> coherences{};
  std::map<std::string, std::vector<int>> not_frf{};  // function name -> lines

  // Record 6's directions and nodes, record 8's abscissa and ID line 1's
  // posture; a record with one direction or none is read as the direct FRF
  // (warned), directions from entity names are noted.
  RecordHead ReadHead(const Uff58Record& r, const std::string& default_pose_id) {
    static const std::regex pose_re(R"(pose=([^\s,]+))");
    RecordHead h;
    h.where = path + ":" + std::to_string(r.line);
    const std::string& where = h.where;
    h.rd = RecordDirection(path, r.record6_line, 52, r.response_direction, r.response_entity, "response");
    h.ed = RecordDirection(path, r.record6_line, 77, r.reference_direction, r.reference_entity, "reference");
    const Direction& rd = h.rd;
    const Direction& ed = h.ed;
    Axis ra = rd.axis, ea = ed.axis;
    if (!rd.known || !ed.known) {
      if (rd.known) ea = ra;
      else if (ed.known) ra = ea;
      out.warnings.push_back(where + ": record 6 gives no " + std::string(!rd.known && !ed.known ? "direction" : !rd.known ? "response direction" : "reference direction") +
                             " (codes " + std::to_string(r.response_direction) + " and " + std::to_string(r.reference_direction) +
                             ", entities \"" + r.response_entity + "\" and \"" + r.reference_entity + "\"); read as the direct FRF " +
                             AxisName(ra) + AxisName(ea) + " (a symmetric tool, or the one direction of a tap test)");
    } else if (rd.from_name || ed.from_name) {
      out.notes.push_back(where + ": directions from the entity names \"" + r.response_entity + "\" and \"" +
                          r.reference_entity + "\" (record 6 codes " + std::to_string(r.response_direction) + " and " +
                          std::to_string(r.reference_direction) + "): response " + (rd.sign < 0 ? "-" : "+") +
                          AxisName(ra) + ", reference " + (ed.sign < 0 ? "-" : "+") + AxisName(ea));
    }
    h.ra = ra;
    h.ea = ea;
    h.resp_node = r.response_node != 0 ? r.response_node : rd.node;
    h.ref_node = r.reference_node != 0 ? r.reference_node : ed.node;
    h.hz = AbscissaToHz(path, r);
    if (r.trailing_values > 0) {
      (r.trailing_all_zero ? out.notes : out.warnings)
          .push_back(where + ": " + std::to_string(r.trailing_values) + (r.trailing_all_zero ? " padding zeros" : " values") +
                     " after the " + std::to_string(r.num_points) + " points record 7 announces are ignored");
    }
    h.pose = default_pose_id;
    if (std::smatch m; std::regex_search(r.id_lines[0], m, pose_re)) h.pose = m[1].str();
    return h;
  }

  // An FRF record (function type 4): its quantity and units, a check that it
  // is not the same FRF twice, and its ordinates as receptance in `out.frfs`.
  void ReadFrf(const Uff58Record& r, const UffUnits* units, const RecordHead& h) {
    const std::string& where = h.where;
    const Axis ra = h.ra, ea = h.ea;
    const int resp_node = h.resp_node, ref_node = h.ref_node;
    if (!r.complex()) {
      out.warnings.push_back(where + ": this FRF has real ordinates (record 7 data type " +
                             std::to_string(r.ordinate_type) + "): read with a zero imaginary part, so without phase");
    }
    const RecordUnits u = FrfRecordUnits(path, r, units, &out.notes, &out.warnings);
    if (!quantity_set) {
      out.file_quantity = u.quantity;
      quantity_set = true;
    }
    FrfKey key;
    key.pose_id = h.pose;
    key.response = ra;
    key.excitation = ea;
    key.response_point = resp_node;
    key.excitation_point = ref_node;
    for (const FrfRecord& o : frf_records) {
      if (o.key == key) {
        throw InputError({path, r.line, 0},
                         "this FRF (" + NodeText(resp_node, ra, ref_node, ea) + ") and the one at line " +
                             std::to_string(o.line) + " are both " + key.ToString() +
                             ": the same FRF twice; name the postures (or runs) with pose=ID in ID line 1");
      }
    }
    const double sign = h.rd.sign * h.ed.sign;
    std::vector<double> fk;
    std::vector<std::complex<double>> hk;
    int zero_lines = 0;
    for (long p = 0; p < r.num_points; ++p) {
      const double f = r.x(p) * h.hz;
      if (f == 0.0 && u.quantity != FrfQuantity::kReceptance) {
        ++zero_lines;
        continue;
      }
      fk.push_back(f);
      hk.push_back(sign * ToReceptance(u.quantity, f, u.factor * r.y(p)));
    }
    if (zero_lines > 0) {
      out.notes.push_back(where + ": the 0 Hz line of " + QuantityWithArticle(u.quantity) +
                          " FRF has no receptance equivalent; it is skipped");
    }
    AtLocation({path, r.line, 0}, "dataset 58 record: ", [&] {
      Frf frf = Frf::FromSamples(Eigen::Map<Eigen::VectorXd>(fk.data(), fk.size()),
                                 Eigen::Map<Eigen::VectorXcd>(hk.data(), hk.size()));
      if (u.quantity == FrfQuantity::kReceptance) CheckLowFrequencyTrend(key, frf, where, &out.warnings);
      out.frfs.Insert(key, std::move(frf));
    });
    frf_records.push_back({key, resp_node, ref_node, r.line});
  }

  // One dataset 58 record: set aside when it is not an FRF, kept for later
  // when it is a coherence, read when it is an FRF.
  void ReadRecord(const Uff58Record& r, const UffUnits* units, const std::string& default_pose_id) {
    if (r.function_type != 4 && r.function_type != 6) {
      not_frf[UffFunctionTypeName(r.function_type) + " (function type " + std::to_string(r.function_type) + ")"]
          .push_back(r.line);
      return;
    }
    const RecordHead h = ReadHead(r, default_pose_id);
    if (r.function_type == 6) {
      if (r.complex()) {
        throw InputError({path, r.record7_line, 0}, "record 7: coherence (function type 6) must be real (data type 2 or "
                                                    "4), got " + std::to_string(r.ordinate_type));
      }
      coherences.push_back({&r, h.pose, h.resp_node, h.ref_node, h.ra, h.ea});
      return;
    }
    ReadFrf(r, units, h);
  }

  // A file without a single FRF is refused, with what it holds instead (other
  // function types, a lone coherence, other datasets).
  void RefuseIfNoFrf() const {
    if (!out.frfs.empty()) return;
    std::string held;
    for (const auto& [name, lines] : not_frf) {
      held += (held.empty() ? "" : "; ") + name + " at line" + (lines.size() > 1 ? "s " : " ");
      for (size_t k = 0; k < lines.size() && k < 5; ++k) held += (k ? ", " : "") + std::to_string(lines[k]);
      if (lines.size() > 5) held += ", ...";
    }
    if (!coherences.empty()) {
      held += std::string(held.empty() ? "" : "; ") + "coherence (function type 6) without its FRF at line " +
              std::to_string(coherences[0].r->line);
    }
    std::string others;
    for (const auto& [n, lines] : file.skipped) others += (others.empty() ? "" : ", ") + n;
    // Time records are what a hammer test records; frf-estimate reads them
    // as UFF58 function type 1 (per hit the force record, then its response
    // records: docs/formats.md §10.1) and writes the FRF CSV read here.
    const bool time_records = std::any_of(file.records.begin(), file.records.end(),
                                          [](const Uff58Record& r) { return r.function_type == 1; });
    throw InputError({path, 0, 0}, "no frequency response function (dataset 58, function type 4) in the file" +
                                       (held.empty() ? std::string() : ": it holds a " + held) +
                                       (others.empty() ? std::string() : (held.empty() ? ": " : "; ") +
                                                                             std::string("datasets ") + others) +
                                       (time_records ? std::string("; to turn impact-hammer time records (per hit the "
                                                                   "force record, then its response records) into an "
                                                                   "FRF file, run frf-estimate on them "
                                                                   "(docs/frf-estimate.md)")
                                                     : std::string()));
  }

  // Notes for what was skipped (records that are not FRFs, other datasets)
  // and for the units of dataset 164 applied.
  void NoteSkippedAndUnits() {
    for (const auto& [name, lines] : not_frf) {
      out.notes.push_back(path + ": skipped " + std::to_string(lines.size()) + " record" + (lines.size() > 1 ? "s" : "") +
                          " that are not FRFs: " + name + " at line " + std::to_string(lines[0]) +
                          (lines.size() > 1 ? " and others" : ""));
    }
    if (!file.skipped.empty()) {
      std::string s;
      for (const auto& [n, lines] : file.skipped) {
        s += (s.empty() ? "" : ", ") + n + " (" + std::to_string(lines.size()) + "x, first at line " + std::to_string(lines[0]) + ")";
      }
      out.notes.push_back(path + ": skipped datasets other than 58 and 164: " + s);
    }
    for (const UffUnits& u : file.units) {
      out.notes.push_back(path + ":" + std::to_string(u.line) + ": units of dataset 164: " + u.description +
                          " (length factor " + Fmt(u.length) + ", force factor " + Fmt(u.force) +
                          "), applied to the records that follow it");
    }
  }

  // Attach a coherence record to its FRF (same nodes and directions, same grid).
  void AttachCoherence(const Coherence& c) {
    const Uff58Record& r = *c.r;
    const std::string where = path + ":" + std::to_string(r.line);
    const FrfRecord* match = nullptr;
    for (const FrfRecord& o : frf_records) {
      if (o.key.pose_id == c.pose && o.key.response == c.ra && o.key.excitation == c.ea &&
          o.resp_node == c.resp_node && o.ref_node == c.ref_node) {
        match = &o;
      }
    }
    if (!match) {
      out.notes.push_back(where + ": coherence record (" + NodeText(c.resp_node, c.ra, c.ref_node, c.ea) +
                          ") has no FRF record with the same nodes and directions; skipped");
      return;
    }
    const Frf& frf = out.frfs.at(match->key);
    if (frf.coherence()) {
      throw InputError({path, r.line, 0}, "second coherence record for " + match->key.ToString() +
                                              " (the first is attached already)");
    }
    const double hz = AbscissaToHz(path, r);
    // The FRF may have lost a 0 Hz line; align by frequency.
    Eigen::VectorXd coh(frf.size());
    long j = 0;
    for (int p = 0; p < frf.size(); ++p) {
      const double fp = frf.freq_hz()(p), tol = 1e-6 * std::max(1.0, fp);
      while (j < r.num_points && r.x(j) * hz < fp - tol) ++j;
      if (j >= r.num_points || std::abs(r.x(j) * hz - fp) > tol) {
        throw InputError({path, r.line, 0}, "coherence record for " + match->key.ToString() +
                                                " is not on the grid of its FRF (line " + std::to_string(match->line) +
                                                ") at " + Fmt(fp) + " Hz");
      }
      coh(p) = r.y(j).real();
    }
    AtLocation({path, r.line, 0}, "coherence record for " + match->key.ToString() + ": ", [&] {
      Frf with = Frf::FromSamples(frf.freq_hz(), frf.receptance(), coh);
      FrfSet rebuilt;
      for (const auto& [k, g] : out.frfs) rebuilt.Insert(k, k == match->key ? with : g);
      out.frfs = std::move(rebuilt);
    });
  }
};

}  // namespace

FrfReadResult ReadUff58(const std::string& path, const std::string& default_pose_id, bool keep_points) {
  const UffFile file = ReadUffFile(path);
  FrfReadResult out;
  Uff58Reader reader{path, file, out};
  for (size_t i = 0; i < file.records.size(); ++i) {
    const UffUnits* units = file.record_units[i] >= 0 ? &file.units[file.record_units[i]] : nullptr;
    reader.ReadRecord(file.records[i], units, default_pose_id);
  }
  reader.RefuseIfNoFrf();
  reader.NoteSkippedAndUnits();
  // Attach coherence records to their FRFs, now that all FRFs are read.
  for (const Coherence& c : reader.coherences) reader.AttachCoherence(c);
  if (!keep_points) DropPointNumbers(path, &out);
  return out;
}

void WriteUff58(std::ostream& os, const FrfSet& frfs, FrfQuantity quantity) {
  int specific = 8;
  std::string unit = "m";
  if (quantity == FrfQuantity::kMobility) {
    specific = 11;
    unit = "m/s";
  } else if (quantity == FrfQuantity::kAccelerance) {
    specific = 12;
    unit = "m/s^2";
  }
  auto axis_line = [&](int spec, int len, int force, const std::string& label, const std::string& units) {
    char buf[128];
    std::snprintf(buf, sizeof(buf), "%10d%5d%5d%5d", spec, len, force, 0);
    return std::string(buf) + " " + PadTo(label, 20) + " " + PadTo(units, 20);
  };
  // The abscissa uses E13.6: 7 significant digits still fit the 13-wide field
  // of the format's E13.5 for positive frequencies, and Fortran input honours
  // an explicit decimal point whatever the descriptor's d.
  auto write_record = [&](const FrfKey& k, const Frf& frf, bool coherence_record) {
    std::vector<int> idx;
    for (int i = 0; i < frf.size(); ++i) {
      if (!coherence_record && frf.freq_hz()(i) == 0.0 && quantity != FrfQuantity::kReceptance) continue;
      idx.push_back(i);
    }
    const long n = static_cast<long>(idx.size());
    bool even = n >= 2;
    double f0 = n > 0 ? frf.freq_hz()(idx[0]) : 0.0;
    double df = n >= 2 ? (frf.freq_hz()(idx[n - 1]) - f0) / (n - 1) : 0.0;
    if (even) {
      const double f0r = std::strtod(Printf("%.6E", f0).c_str(), nullptr);
      const double dfr = std::strtod(Printf("%.6E", df).c_str(), nullptr);
      const double tol = 1e-9 * frf.freq_hz()(idx[n - 1]);
      for (long p = 0; p < n && even; ++p) {
        even = std::abs(frf.freq_hz()(idx[p]) - (f0r + p * dfr)) <= tol;
      }
    }
    os << "    -1\n    58\n";
    os << Pad80("pose=" + k.pose_id + " tool-tip " +
                (coherence_record ? std::string("coherence") : ToString(quantity))) << '\n';
    os << Pad80(std::string(coherence_record ? "C" : "H") + AxisName(k.response) + AxisName(k.excitation)) << '\n';
    os << Pad80("robomach") << '\n' << Pad80("NONE") << '\n' << Pad80("NONE") << '\n';
    char buf[256];
    std::snprintf(buf, sizeof(buf), "%5d%10d%5d%10d %10s%10d%4d %10s%10d%4d", coherence_record ? 6 : 4, 0, 0, 0,
                  "tip", 1, static_cast<int>(k.response) + 1, "tip", 1, static_cast<int>(k.excitation) + 1);
    os << buf << '\n';
    std::snprintf(buf, sizeof(buf), "%10d%10ld%10d%13.6E%13.6E%13.6E", coherence_record ? 4 : 6, n,
                  even ? 1 : 0, even ? f0 : 0.0, even ? df : 0.0, 0.0);
    os << buf << '\n';
    os << axis_line(18, 0, 0, "NONE", "Hz") << '\n';
    if (coherence_record) {
      os << axis_line(0, 0, 0, "NONE", "none") << '\n';
      os << axis_line(0, 0, 0, "NONE", "none") << '\n';
    } else {
      os << axis_line(specific, 1, 0, "NONE", unit) << '\n';
      os << axis_line(13, 0, 1, "NONE", "N") << '\n';
    }
    os << axis_line(0, 0, 0, "NONE", "none") << '\n';
    if (coherence_record) {
      const Eigen::VectorXd& c = *frf.coherence();
      if (even) {
        for (long p = 0; p < n; ++p) {
          os << Printf("%20.12E", c(idx[p])) << ((p % 4 == 3 || p == n - 1) ? "\n" : "");
        }
      } else {
        for (long p = 0; p < n; ++p) {
          os << Printf("%13.6E", frf.freq_hz()(idx[p])) << Printf("%20.12E", c(idx[p]))
             << ((p % 2 == 1 || p == n - 1) ? "\n" : "");
        }
      }
    } else {
      for (long p = 0; p < n; ++p) {
        const double f = frf.freq_hz()(idx[p]);
        const std::complex<double> v = FromReceptance(quantity, f, frf.receptance()(idx[p]));
        if (even) {
          os << Printf("%20.12E", v.real()) << Printf("%20.12E", v.imag())
             << ((p % 2 == 1 || p == n - 1) ? "\n" : "");
        } else {
          os << Printf("%13.6E", f) << Printf("%20.12E", v.real()) << Printf("%20.12E", v.imag()) << '\n';
        }
      }
    }
    os << "    -1\n";
  };
  for (const auto& [k, frf] : frfs) {
    write_record(k, frf, false);
    if (frf.coherence()) write_record(k, frf, true);
  }
}

void WriteUff58(const std::string& path, const FrfSet& frfs, FrfQuantity quantity) {
  WriteFileAtomically(path, [&](std::ostream& os) { WriteUff58(os, frfs, quantity); });
}

double RoundToUffPrecision(double v) {
  if (v == 0.0 || !std::isfinite(v)) return v;
  char buf[40];
  std::snprintf(buf, sizeof(buf), "%.12E", v);
  return std::strtod(buf, nullptr);
}

}  // namespace robomach::io
