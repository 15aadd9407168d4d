#include "robomach/io/hammer_records.h"

#include <cmath>
#include <cstdio>
#include <algorithm>
#include <filesystem>
#include <map>
#include <optional>
#include <set>
#include <stdexcept>

#include "robomach/common/frames.h"
#include "robomach/common/number_format.h"
#include "robomach/io/atomic_file.h"
#include "robomach/io/csv_table.h"
#include "robomach/io/uff58.h"

namespace robomach::io {
namespace {

using calibration::ImpactRecord;
using calibration::ResponseQuantity;

bool EndsWith(const std::string& s, const std::string& suffix) {
  return s.size() > suffix.size() && s.compare(s.size() - suffix.size(), suffix.size(), suffix) == 0;
}

// A number of a required column, with the column's position in the error.
double NumberAt(const CsvTable& t, int row, int col) {
  try {
    return t.Number(row, t.header()[col]);
  } catch (const InputError& e) {
    throw InputError({e.where().path, e.where().line, col + 1}, e.message());
  }
}

InputError ErrorAtCell(const CsvTable& t, int row, int col, const std::string& message) {
  return InputError({t.path(), t.line(row), col + 1}, "column " + t.header()[col] + ": " + message);
}

struct FileHits {
  std::vector<std::string> channel_columns;
  std::vector<ImpactRecord> hits;
};

FileHits ReadOne(const std::string& path, bool prefix_ids) {
  const CsvTable t = CsvTable::ReadFile(path);
  const std::string stem = std::filesystem::path(path).stem().string();
  for (const std::string& h : t.header()) {
    if (h.find(';') != std::string::npos || h.find('\t') != std::string::npos) {
      throw InputError({path, t.header_line(), 0},
                       "the header '" + h + "' looks separated by ';' or tabs; this format is comma-separated "
                       "with '.' decimals (columns time_s, force_N, responses <name>_m, <name>_m_per_s or "
                       "<name>_m_per_s2, optional hit)");
    }
  }
  t.RequireColumn("time_s", "hammer");
  t.RequireColumn("force_N", "hammer");
  const int c_time = t.ColumnIndex("time_s"), c_force = t.ColumnIndex("force_N"), c_hit = t.ColumnIndex("hit");
  FileHits out;
  std::vector<int> c_resp;
  for (int c = 0; c < static_cast<int>(t.header().size()); ++c) {
    const std::string& h = t.header()[c];
    if (c == c_time || c == c_force || c == c_hit) continue;
    ResponseQuantity q;
    std::string name;
    if (!ParseResponseColumn(h, &q, &name)) {
      throw InputError({path, t.header_line(), c + 1},
                       "unknown column '" + h + "'; expected time_s, force_N, hit, or a response named "
                       "<name>_m (displacement), <name>_m_per_s (velocity) or <name>_m_per_s2 (acceleration)");
    }
    c_resp.push_back(c);
    out.channel_columns.push_back(h);
  }
  if (c_resp.empty()) {
    throw InputError({path, t.header_line(), 0},
                     "no response column; name one <name>_m, <name>_m_per_s or <name>_m_per_s2 (the unit is "
                     "part of the name)");
  }
  if (t.num_rows() == 0) throw InputError({path, t.header_line(), 0}, "no data rows after the header");

  // Split into hits: contiguous blocks of equal `hit` cells.
  struct Block {
    std::string id;
    int first, last;  // rows
  };
  std::vector<Block> blocks;
  std::map<std::string, int> seen;  // id -> block index
  for (int r = 0; r < t.num_rows(); ++r) {
    std::string id = stem;
    if (c_hit >= 0) {
      id = t.Cell(r, c_hit);
      if (id.empty()) throw ErrorAtCell(t, r, c_hit, "expected a hit id, got an empty cell");
    }
    if (!blocks.empty() && blocks.back().id == id) {
      blocks.back().last = r;
      continue;
    }
    if (auto it = seen.find(id); it != seen.end()) {
      const Block& b = blocks[it->second];
      throw ErrorAtCell(t, r, c_hit, "hit '" + id + "' appears again (its rows were lines " +
                                         std::to_string(t.line(b.first)) + "-" + std::to_string(t.line(b.last)) +
                                         "); the rows of one hit must be contiguous");
    }
    seen[id] = static_cast<int>(blocks.size());
    blocks.push_back({id, r, r});
  }
  for (const Block& b : blocks) {
    const int n = b.last - b.first + 1;
    ImpactRecord rec;
    rec.id = c_hit >= 0 && prefix_ids ? stem + "#" + b.id : b.id;
    rec.source = path + ":" + std::to_string(t.line(b.first));
    rec.force_N.resize(n);
    rec.response.resize(n, static_cast<int>(c_resp.size()));
    Eigen::VectorXd time(n);
    for (int i = 0; i < n; ++i) {
      const int r = b.first + i;
      time(i) = NumberAt(t, r, c_time);
      if (i > 0 && !(time(i) > time(i - 1))) {
        throw ErrorAtCell(t, r, c_time, "expected a time > " + FormatNumber(time(i - 1), 10) + " (the previous row), got " +
                                            FormatNumber(time(i), 10) + "; time must increase within a hit");
      }
      rec.force_N(i) = NumberAt(t, r, c_force);
      for (size_t k = 0; k < c_resp.size(); ++k) rec.response(i, static_cast<int>(k)) = NumberAt(t, r, c_resp[k]);
    }
    if (n < 16) {
      throw InputError({path, t.line(b.first), 0}, "hit '" + b.id + "' has " + std::to_string(n) +
                                                       " samples (lines " + std::to_string(t.line(b.first)) + "-" +
                                                       std::to_string(t.line(b.last)) + "); at least 16 are needed");
    }
    // The median step finds the odd row out; the mean over the record
    // gives the rate to the precision of the written times.
    std::vector<double> steps(n - 1);
    for (int i = 1; i < n; ++i) steps[i - 1] = time(i) - time(i - 1);
    std::nth_element(steps.begin(), steps.begin() + (n - 1) / 2, steps.end());
    const double median = steps[(n - 1) / 2];
    for (int i = 1; i < n; ++i) {
      const double step = time(i) - time(i - 1);
      if (std::abs(step - median) > 0.01 * median) {
        throw ErrorAtCell(t, b.first + i, c_time,
                          "uneven sampling: step " + FormatNumber(step, 10) + " s from the previous row, the hit's usual "
                          "step is " + FormatNumber(median, 10) + " s (more than 1 % apart; a missing or repeated sample?)");
      }
    }
    const double dt = (time(n - 1) - time(0)) / (n - 1);
    rec.start_time_s = time(0);
    rec.sample_rate_hz = 1.0 / dt;
    // Written times are rounded, so 1/dt misses the acquisition's rate by
    // up to ~2δ/T (δ: the largest deviation of a time from the even grid,
    // T: the record length). Rates are whole hertz on every acquisition
    // system we know of (1024, 5120, 51200 Hz): snap to one within that.
    double dev = 0.0;
    for (int i = 0; i < n; ++i) dev = std::max(dev, std::abs(time(i) - (time(0) + i * dt)));
    const double whole = std::round(rec.sample_rate_hz);
    const double tol = (2.0 * dev / (time(n - 1) - time(0)) + 1e-12) * rec.sample_rate_hz;
    if (whole > 0.0 && std::abs(whole - rec.sample_rate_hz) <= tol) rec.sample_rate_hz = whole;
    out.hits.push_back(std::move(rec));
  }
  return out;
}

// ------------------------------------------------------------ UFF58 --
//
// Time records (dataset 58, function type 1) as data acquisition systems
// export a hammer test: per hit one force record and the response records
// of that hit, in file order. A hit starts at each force record; the
// response records after it, up to the next force record, are its
// responses. A record is a force if record 9 says excitation or reaction
// force (specific data type 13 or 9) or its unit is a force; a response if
// it says displacement, velocity or acceleration (8, 11, 12) or its unit is
// a length, m/s or m/s². Units: the record 9 label (e.g. "g", "mm/s^2",
// "lbf"), else dataset 164 with record 9's exponents, else SI. A response
// channel is named by its node and direction, "n<node>_<axis>" (a negative
// direction is read with its sign flipped, along +axis), so that its
// direction comes from the name (ChannelKeys); a force record with a
// negative direction is likewise read along +axis.

struct UffTimeRecord {
  const Uff58Record* r;
  bool force{false};
  ResponseQuantity quantity{ResponseQuantity::kAcceleration};
  double factor{1.0};  // SI = factor × stored
  std::string name;     // response channel name
};

UnitDimension LabelAt(const std::string& path, const UffAxis& a, const std::string& record) {
  return AtLocation({path, a.line, 48}, record + " units label: ", [&] { return ParseUnitLabel(a.units); });
}

UffTimeRecord ClassifyTimeRecord(const std::string& path, const Uff58Record& r, const UffUnits* units) {
  UffTimeRecord out;
  out.r = &r;
  const int spec = r.ordinate.specific_type;
  std::optional<bool> force_by_code;
  std::optional<ResponseQuantity> q_by_code;
  switch (spec) {
    case 13: case 9: force_by_code = true; break;
    case 8: q_by_code = ResponseQuantity::kDisplacement; break;
    case 11: q_by_code = ResponseQuantity::kVelocity; break;
    case 12: q_by_code = ResponseQuantity::kAcceleration; break;
    case 0: case 1: break;
    default:
      throw InputError({path, r.ordinate.line, 1},
                       "record 9: ordinate specific data type " + std::to_string(spec) +
                           " is not a hammer force (13 excitation force, 9 reaction force) or a response (8 "
                           "displacement, 11 velocity, 12 acceleration)");
  }
  const UnitDimension u = LabelAt(path, r.ordinate, "record 9");
  std::optional<bool> force_by_unit;
  std::optional<ResponseQuantity> q_by_unit;
  if (u.given) {
    if (u.force == 1 && u.length == 0 && u.time == 0) force_by_unit = true;
    else if (u.force == 0 && u.length == 1 && u.time == 0) q_by_unit = ResponseQuantity::kDisplacement;
    else if (u.force == 0 && u.length == 1 && u.time == -1) q_by_unit = ResponseQuantity::kVelocity;
    else if (u.force == 0 && u.length == 1 && u.time == -2) q_by_unit = ResponseQuantity::kAcceleration;
    else {
      throw InputError({path, r.ordinate.line, 48},
                       "record 9 unit \"" + r.ordinate.units + "\" is m^" + std::to_string(u.length) + " N^" +
                           std::to_string(u.force) + " s^" + std::to_string(u.time) +
                           ", neither a force (N) nor a displacement, velocity or acceleration (m, m/s, m/s^2)");
    }
  }
  const bool is_force = force_by_code.value_or(false) || force_by_unit.value_or(false);
  const bool is_response = q_by_code.has_value() || q_by_unit.has_value();
  if (is_force && is_response) {
    throw InputError({path, r.ordinate.line, 1},
                     "record 9: specific data type " + std::to_string(spec) + " and unit \"" + r.ordinate.units +
                         "\" disagree on whether this is the force or a response; correct one of them in the export");
  }
  if (!is_force && !is_response) {
    throw InputError({path, r.ordinate.line, 1},
                     "record 9 gives neither a specific data type (" + std::to_string(spec) +
                         ") nor a unit, so the force cannot be told from the responses: export the force with "
                         "type 13 (or unit N) and the responses with 8, 11 or 12 (or m, m/s, m/s^2)");
  }
  if (q_by_code && q_by_unit && *q_by_code != *q_by_unit) {
    throw InputError({path, r.ordinate.line, 1},
                     "record 9: specific data type " + std::to_string(spec) + " and unit \"" + r.ordinate.units +
                         "\" name different quantities; correct one of them in the export");
  }
  out.force = is_force;
  if (!is_force) out.quantity = q_by_unit ? *q_by_unit : *q_by_code;
  if (u.given) {
    out.factor = u.factor;
  } else if (units && (r.ordinate.length_exponent || r.ordinate.force_exponent)) {
    out.factor = std::pow(units->length, -r.ordinate.length_exponent) * std::pow(units->force, -r.ordinate.force_exponent);
  }
  if (out.force) {
    // The hammer along -axis (a negative direction code): read along +axis,
    // as the responses are.
    if (r.response_direction < 0) out.factor = -out.factor;
  } else {
    const int d = r.response_direction;
    if (std::abs(d) >= 4) {
      throw InputError({path, r.record6_line, 52},
                       "record 6: response direction " + std::to_string(d) +
                           " is not translational (1/-1 x, 2/-2 y, 3/-3 z, 0 scalar)");
    }
    out.name = "n" + std::to_string(r.response_node);
    if (d != 0) {
      out.name += std::string("_") + "xyz"[std::abs(d) - 1];
      if (d < 0) out.factor = -out.factor;
    }
  }
  return out;
}

// Seconds per stored abscissa unit of a time record.
double AbscissaToSeconds(const std::string& path, const Uff58Record& r) {
  const int spec = r.abscissa.specific_type;
  if (spec != 0 && spec != 1 && spec != 17) {
    throw InputError({path, r.abscissa.line, 1}, "record 8: abscissa specific data type " + std::to_string(spec) +
                                                     " is not time (17): a time record is a function of time");
  }
  const UnitDimension d = LabelAt(path, r.abscissa, "record 8");
  if (!d.given) return 1.0;
  if (d.time != 1 || d.length || d.force) {
    throw InputError({path, r.abscissa.line, 48}, "record 8: abscissa unit \"" + r.abscissa.units + "\" is not a time");
  }
  return d.factor;
}

FileHits ReadOneUff(const std::string& path, bool prefix_ids) {
  const UffFile file = ReadUffFile(path);
  const std::string stem = std::filesystem::path(path).stem().string();
  if (file.records.empty()) {
    throw InputError({path, 0, 0}, "no dataset 58 record: a UFF hammer record file holds the time records "
                                   "(dataset 58, function type 1) of the force and responses of each hit");
  }
  std::vector<UffTimeRecord> recs;
  for (size_t i = 0; i < file.records.size(); ++i) {
    const Uff58Record& r = file.records[i];
    if (r.function_type != 1) {
      throw InputError({path, r.record6_line, 1},
                       "record 6: function type " + std::to_string(r.function_type) + " (" +
                           UffFunctionTypeName(r.function_type) +
                           "); frf-estimate reads time responses (function type 1), the raw records of each hit" +
                           (r.function_type == 4 ? " (an FRF file is read by frf-calibrate, model-audit, stability-lobes)"
                                                 : ""));
    }
    if (r.complex()) {
      throw InputError({path, r.record7_line, 1}, "record 7: ordinate data type " + std::to_string(r.ordinate_type) +
                                                      " is complex; a time record is real (2 or 4)");
    }
    const UffUnits* units = file.record_units[i] >= 0 ? &file.units[file.record_units[i]] : nullptr;
    recs.push_back(ClassifyTimeRecord(path, r, units));
  }
  if (!recs.front().force) {
    throw InputError({path, recs.front().r->line, 0},
                     "the first record is a response (" + recs.front().name +
                         "); each hit starts with its force record, followed by its response records");
  }
  // Groups: a force record and the responses after it.
  std::vector<std::vector<const UffTimeRecord*>> groups;
  for (const UffTimeRecord& t : recs) {
    if (t.force) groups.emplace_back();
    groups.back().push_back(&t);
  }
  // Load cases as hit ids when every hit has its own.
  std::set<int> cases;
  for (const auto& g : groups) cases.insert(g.front()->r->load_case);
  const bool by_case = cases.size() == groups.size() && groups.size() > 1;
  FileHits out;
  std::vector<std::string> names;  // channel names of the first hit, in order
  for (size_t h = 0; h < groups.size(); ++h) {
    const auto& g = groups[h];
    const Uff58Record& f = *g.front()->r;
    const std::string hid = by_case ? std::to_string(f.load_case) : std::to_string(h + 1);
    const std::string where = path + ":" + std::to_string(f.line);
    if (g.size() < 2) throw InputError({path, f.line, 0}, "hit " + hid + ": a force record without response records");
    std::vector<std::string> mine;
    for (size_t k = 1; k < g.size(); ++k) {
      const UffTimeRecord& t = *g[k];
      if (t.r->load_case != f.load_case && by_case) {
        throw InputError({path, t.r->line, 0}, "response record of load case " + std::to_string(t.r->load_case) +
                                                   " after the force record of load case " + std::to_string(f.load_case) +
                                                   " (line " + std::to_string(f.line) + "); each hit's responses follow its force");
      }
      if (std::find(mine.begin(), mine.end(), t.name) != mine.end()) {
        throw InputError({path, t.r->line, 0}, "hit " + hid + ": a second response record of " + t.name +
                                                   " (node " + std::to_string(t.r->response_node) + ", direction " +
                                                   std::to_string(t.r->response_direction) + ")");
      }
      mine.push_back(t.name);
    }
    if (h == 0) {
      names = mine;
      for (size_t k = 1; k < g.size(); ++k) {
        const char* suffix = g[k]->quantity == ResponseQuantity::kDisplacement ? "_m"
                             : g[k]->quantity == ResponseQuantity::kVelocity   ? "_m_per_s"
                                                                               : "_m_per_s2";
        out.channel_columns.push_back(g[k]->name + suffix);
      }
    } else if (std::set<std::string>(mine.begin(), mine.end()) != std::set<std::string>(names.begin(), names.end())) {
      std::string a, b;
      for (const auto& c : names) a += (a.empty() ? "" : ", ") + c;
      for (const auto& c : mine) b += (b.empty() ? "" : ", ") + c;
      throw InputError({path, f.line, 0}, "hit " + hid + " has the responses " + b + ", the first hit " + a +
                                              "; every hit must have the same responses");
    }
    // One time grid per hit, the same for its force and responses.
    const double s_per_unit = AbscissaToSeconds(path, f);
    for (const UffTimeRecord* t : g) {
      const Uff58Record& r = *t->r;
      if (!r.even) {
        throw InputError({path, r.record7_line, 21}, "record 7: uneven abscissa; a time record must be evenly "
                                                         "sampled (record 7 field 3 = 1, with x_min and dx)");
      }
      if (!(r.dx > 0.0)) {
        throw InputError({path, r.record7_line, 44}, "record 7: dx " + FormatNumber(r.dx, 10) + " is not > 0");
      }
      if (r.num_points != f.num_points || std::abs(r.dx - f.dx) > 1e-9 * f.dx ||
          std::abs(r.x_min - f.x_min) > 1e-6 * f.dx * f.num_points ||
          std::abs(AbscissaToSeconds(path, r) - s_per_unit) > 1e-12 * s_per_unit) {
        throw InputError({path, r.line, 0}, "hit " + hid + ": this record's time grid (" + std::to_string(r.num_points) +
                                                " points, x_min " + FormatNumber(r.x_min, 10) + ", dx " +
                                                FormatNumber(r.dx, 10) + ") differs from its force record's (" +
                                                std::to_string(f.num_points) + " points, x_min " +
                                                FormatNumber(f.x_min, 10) + ", dx " + FormatNumber(f.dx, 10) +
                                                ", line " + std::to_string(f.line) + ")");
      }
    }
    const long n = f.num_points;
    if (n < 16) {
      throw InputError({path, f.line, 0}, "hit " + hid + " has " + std::to_string(n) + " samples; at least 16 are needed");
    }
    ImpactRecord rec;
    rec.id = prefix_ids ? stem + "#" + hid : hid;
    rec.source = where;
    rec.start_time_s = f.x_min * s_per_unit;
    rec.sample_rate_hz = 1.0 / (f.dx * s_per_unit);
    // dx is written with 6 significant digits (E13.5): a rate within that
    // rounding of a whole number of hertz is that number (as for the CSV).
    const double whole = std::round(rec.sample_rate_hz);
    if (whole > 0.0 && std::abs(whole - rec.sample_rate_hz) <= 5e-6 * rec.sample_rate_hz) rec.sample_rate_hz = whole;
    rec.force_N = g.front()->factor * f.y.real();
    rec.response.resize(n, static_cast<Eigen::Index>(names.size()));
    for (size_t k = 1; k < g.size(); ++k) {
      const auto c = std::find(names.begin(), names.end(), g[k]->name) - names.begin();
      rec.response.col(c) = g[k]->factor * g[k]->r->y.real();
    }
    out.hits.push_back(std::move(rec));
  }
  return out;
}

}  // namespace

bool ParseResponseColumn(const std::string& column, ResponseQuantity* quantity, std::string* name) {
  // Longest suffix first: "_m_per_s2" also ends in "_m_per_s"'s prefix.
  static const std::pair<const char*, ResponseQuantity> kSuffixes[] = {
      {"_m_per_s2", ResponseQuantity::kAcceleration},
      {"_m_per_s", ResponseQuantity::kVelocity},
      {"_m", ResponseQuantity::kDisplacement}};
  for (const auto& [suffix, q] : kSuffixes) {
    if (EndsWith(column, suffix)) {
      *quantity = q;
      *name = column.substr(0, column.size() - std::string(suffix).size());
      return true;
    }
  }
  return false;
}

HammerRecords ReadHammerRecords(const std::vector<std::string>& paths) {
  if (paths.empty()) throw std::invalid_argument("ReadHammerRecords: no file given");
  HammerRecords out;
  std::map<std::string, std::string> where;  // hit id -> source
  for (size_t f = 0; f < paths.size(); ++f) {
    FileHits fh = LooksLikeUff(paths[f]) ? ReadOneUff(paths[f], paths.size() > 1) : ReadOne(paths[f], paths.size() > 1);
    if (f == 0) {
      out.channel_columns = fh.channel_columns;
      for (const std::string& c : fh.channel_columns) {
        calibration::ResponseChannel ch;
        ParseResponseColumn(c, &ch.quantity, &ch.name);
        out.channels.push_back(ch);
      }
    } else if (std::set<std::string>(fh.channel_columns.begin(), fh.channel_columns.end()) !=
               std::set<std::string>(out.channel_columns.begin(), out.channel_columns.end())) {
      std::string a, b;
      for (const auto& c : out.channel_columns) a += (a.empty() ? "" : ", ") + c;
      for (const auto& c : fh.channel_columns) b += (b.empty() ? "" : ", ") + c;
      throw InputError({paths[f], 0, 0}, "response columns " + b + " differ from those of " + paths[0] + " (" + a +
                                             "); every file must have the same responses");
    } else {
      // Same set, maybe another order: reorder to the first file's.
      for (ImpactRecord& rec : fh.hits) {
        Eigen::MatrixXd r(rec.response.rows(), rec.response.cols());
        for (size_t k = 0; k < out.channel_columns.size(); ++k) {
          const auto it = std::find(fh.channel_columns.begin(), fh.channel_columns.end(), out.channel_columns[k]);
          r.col(static_cast<int>(k)) = rec.response.col(static_cast<int>(it - fh.channel_columns.begin()));
        }
        rec.response = std::move(r);
      }
    }
    for (ImpactRecord& rec : fh.hits) {
      if (auto it = where.find(rec.id); it != where.end()) {
        throw InputError({paths[f], 0, 0}, "hit id '" + rec.id + "' (" + rec.source + ") was already read from " +
                                               it->second + "; hit ids must be unique");
      }
      where[rec.id] = rec.source;
      if (!out.hits.empty()) {
        const double fs0 = out.hits.front().sample_rate_hz;
        if (std::abs(rec.sample_rate_hz - fs0) > 1e-4 * fs0) {
          throw InputError({paths[f], 0, 0}, "hit '" + rec.id + "' (" + rec.source + ") is sampled at " +
                                                 FormatNumber(rec.sample_rate_hz, 10) + " Hz, hit '" + out.hits.front().id +
                                                 "' at " + FormatNumber(fs0, 10) + " Hz; all hits need one sample rate");
        }
      }
      out.hits.push_back(std::move(rec));
    }
  }
  return out;
}

void WriteEstimatedFrfCsv(const std::string& path, const dynamics::FrfSet& frfs, FrfQuantity quantity,
                          int averages, const std::vector<std::pair<std::string, std::string>>& metadata) {
  for (const auto& [key, value] : metadata) {
    if (key.empty() || key.find_first_of(": \t\r\n") != std::string::npos || key == "quantity" ||
        key == "averages" || value.find_first_of("\r\n") != std::string::npos) {
      throw std::invalid_argument("WriteEstimatedFrfCsv: bad metadata '" + key + ": " + value + "'");
    }
  }
  WriteFileAtomically(path, [&](std::ostream& os) {
    for (const auto& [key, value] : metadata) os << "# " << key << ": " << value << '\n';
    WriteFrfCsv(os, frfs, quantity, averages);
  });
}

FrfQuantity QuantityOf(calibration::ResponseQuantity q) {
  switch (q) {
    case calibration::ResponseQuantity::kDisplacement: return FrfQuantity::kReceptance;
    case calibration::ResponseQuantity::kVelocity: return FrfQuantity::kMobility;
    case calibration::ResponseQuantity::kAcceleration: return FrfQuantity::kAccelerance;
  }
  return FrfQuantity::kReceptance;
}

EstimatedFrfs ToEstimatedFrfs(const calibration::FrfEstimateResult& r, const HammerRecords& rec,
                              const std::vector<dynamics::FrfKey>& keys, bool h2) {
  if (r.status != calibration::FrfEstimateStatus::kOk) throw std::invalid_argument("ToEstimatedFrfs: no estimate");
  if (keys.size() != rec.channels.size() || r.channels.size() != rec.channels.size()) {
    throw std::invalid_argument("ToEstimatedFrfs: expected one key per response channel");
  }
  EstimatedFrfs out;
  std::vector<std::pair<dynamics::FrfKey, int>> order;
  for (size_t c = 0; c < keys.size(); ++c) order.push_back({keys[c], static_cast<int>(c)});
  std::sort(order.begin(), order.end());
  for (const auto& [key, c] : order) {
    const auto& ch = r.channels[c];
    const Eigen::VectorXcd& h = h2 ? ch.h2 : ch.h1;
    const FrfQuantity in_q = QuantityOf(rec.channels[c].quantity);
    Eigen::VectorXcd hr(h.size());
    for (int k = 0; k < h.size(); ++k) hr(k) = ToReceptance(in_q, r.freq_hz(k), h(k));
    out.frfs.Insert(key, dynamics::Frf::FromSamples(r.freq_hz, hr, ch.coherence));
    out.labels.push_back(rec.channels[c].name + " (H" + std::string(1, AxisName(key.response)) +
                         std::string(1, AxisName(key.excitation)) + ")");
    out.channel_of.push_back(c);
  }
  std::string rejected;
  for (const auto& hit : r.hits) {
    if (hit.status == calibration::HitStatus::kAccepted) continue;
    rejected += (rejected.empty() ? "" : ", ") + hit.id + " (" + calibration::ToString(hit.status) + ")";
  }
  auto& meta = out.metadata;
  meta.push_back({"estimator", h2 ? "H2" : "H1"});
  meta.push_back({"hits_averaged", std::to_string(r.averages) + " of " + std::to_string(r.hits.size())});
  if (!rejected.empty()) meta.push_back({"hits_rejected", rejected});
  meta.push_back({"force_window_s", r.force_window_s < 0 ? std::string("off") : FormatDouble(r.force_window_s)});
  meta.push_back({"exponential_window_tau_s",
                  r.exponential_tau_s > 0 ? FormatDouble(r.exponential_tau_s) : std::string("none")});
  if (r.exponential_tau_s > 0) {
    meta.push_back({"exponential_window_note",
                    "fitted damping ratios are too high by 1/(tau*omega_n); correct them with "
                    "calibration::CorrectExponentialWindowDamping"});
  }
  return out;
}

std::vector<double> ResponseRanges(const HammerRecords& rec, const std::map<std::string, double>& ranges) {
  if (ranges.empty()) return {};
  std::vector<double> out(rec.channels.size(), 0.0);
  for (const auto& [name, value] : ranges) {
    const std::string entry = name + "=" + FormatDouble(value);
    size_t c = 0;
    while (c < rec.channels.size() && rec.channels[c].name != name) ++c;
    if (c == rec.channels.size()) throw std::invalid_argument(entry + ": no response channel '" + name + "'");
    if (!(value >= 0.0) || !std::isfinite(value)) {
      throw std::invalid_argument(entry + ": expected a finite range >= 0 in the channel's SI unit (0 = unknown)");
    }
    out[c] = value;
  }
  return out;
}

std::vector<dynamics::FrfKey> ChannelKeys(const HammerRecords& rec, const std::string& pose_id, Axis excitation,
                                          const std::map<std::string, std::string>& directions) {
  for (const auto& [name, v] : directions) {
    bool known = false;
    for (const auto& c : rec.channels) known = known || c.name == name;
    if (!known) throw std::invalid_argument(name + "=" + v + ": no response channel '" + name + "'");
  }
  std::vector<dynamics::FrfKey> keys;
  for (const auto& ch : rec.channels) {
    const std::string& name = ch.name;
    Axis response = Axis::kX;
    if (const auto it = directions.find(name); it != directions.end()) {
      try {
        response = ParseAxis(it->second);
      } catch (const std::invalid_argument& e) {
        throw std::invalid_argument(name + ": " + e.what());
      }
    } else {
      // The suffix through the one axis parser (a capital too, "acc_X").
      const bool suffix = name.size() == 1 || (name.size() >= 2 && name[name.size() - 2] == '_');
      bool named = false;
      if (suffix) {
        try {
          response = ParseAxis(name.substr(name.size() - 1));
          named = true;
        } catch (const std::invalid_argument&) {
        }
      }
      if (!named) {
        throw std::invalid_argument(name + ": response channel '" + name +
                                    "' has no direction in its name (…_x, …_y, …_z); give " + name +
                                    "=x (or y, z)");
      }
    }
    const dynamics::FrfKey key{pose_id, response, excitation};
    for (size_t k = 0; k < keys.size(); ++k) {
      if (keys[k] == key) {
        throw std::invalid_argument(name + ": response channels '" + rec.channels[k].name + "' and '" + name +
                                    "' both give " + key.ToString() + "; give a direction for one of them");
      }
    }
    keys.push_back(key);
  }
  return keys;
}

nlohmann::json FrfEstimateSummaryJson(const calibration::FrfEstimateResult& r, const HammerRecords& rec,
                                      const std::vector<dynamics::FrfKey>& keys) {
  nlohmann::json j;
  j["sample_rate_hz"] = r.sample_rate_hz;
  j["block_samples"] = r.block_samples;
  j["line_spacing_hz"] = r.block_samples > 0 ? r.sample_rate_hz / r.block_samples : 0.0;
  j["averages"] = r.averages;
  j["force_window_s"] = r.force_window_s;
  j["force_window_pre_s"] = r.force_window_pre_s;
  j["exponential_window_tau_s"] = r.exponential_tau_s;
  j["leakage"] = r.leakage;
  j["warnings"] = r.warnings;
  nlohmann::json hits = nlohmann::json::array();
  for (const auto& h : r.hits) {
    hits.push_back({{"id", h.id},
                    {"source", h.source},
                    {"status", calibration::ToString(h.status)},
                    {"hit_time_s", h.hit_time_s},
                    {"peak_force_N", h.peak_force_N},
                    {"pulse_duration_s", h.pulse_duration_s},
                    {"notes", h.notes}});
  }
  j["hits"] = hits;
  nlohmann::json chans = nlohmann::json::array();
  for (size_t c = 0; c < rec.channels.size(); ++c) {
    nlohmann::json cj = {{"name", rec.channels[c].name},
                         {"column", rec.channel_columns[c]},
                         {"quantity", ToString(QuantityOf(rec.channels[c].quantity))},
                         {"response", std::string(1, AxisName(keys.at(c).response))},
                         {"excitation", std::string(1, AxisName(keys.at(c).excitation))}};
    if (r.status == calibration::FrfEstimateStatus::kOk) {
      const auto& g = r.channels[c].coherence;
      cj["lines"] = g.size();
      cj["lines_coherence_above_0_9"] = (g.array() > 0.9).count();
      cj["min_coherence"] = g.minCoeff();
    }
    chans.push_back(cj);
  }
  j["channels"] = chans;
  return j;
}

}  // namespace robomach::io
