#include "robomach/io/file_kind.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <vector>

#include "text.h"

namespace robomach::io {
namespace {

bool StartsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

FileSniff Kind(FileKind k, std::string description) { return {k, std::move(description), ""}; }

// A YAML mapping line: "key:" or "key: value", the key without commas.
bool LooksLikeYamlKey(std::string_view line) {
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == ',' || c == '"' || c == '\'') return false;
    if (c == ':') return i > 0 && (i + 1 == line.size() || line[i + 1] == ' ' || line[i + 1] == '\t');
  }
  return false;
}

// A line of a Siemens part program or archive (formats.md §8.4): the
// "%_N_NAME_MPF" header, an assignment "$NAME[...]=..." (optionally after a
// block number "N10 "), or "CHANDATA(".
bool LooksLikeMpfLine(std::string_view line) {
  if (StartsWith(line, "%_N_") || StartsWith(line, "CHANDATA(")) return true;
  if (line.size() > 1 && (line[0] == 'N' || line[0] == 'n') && std::isdigit(static_cast<unsigned char>(line[1]))) {
    size_t i = 1;
    while (i < line.size() && std::isdigit(static_cast<unsigned char>(line[i]))) ++i;
    while (i < line.size() && (line[i] == ' ' || line[i] == '\t')) ++i;
    line.remove_prefix(i);
  }
  return line.size() > 1 && line[0] == '$' && std::isalpha(static_cast<unsigned char>(line[1])) &&
         line.find('=') != std::string_view::npos;
}

// The header cells of a CSV line, trimmed.
std::vector<std::string> HeaderCells(std::string_view line) {
  std::vector<std::string> cells;
  size_t pos = 0;
  while (true) {
    const size_t comma = line.find(',', pos);
    cells.push_back(Trim(line.substr(pos, comma == std::string_view::npos ? std::string_view::npos : comma - pos)));
    if (comma == std::string_view::npos) break;
    pos = comma + 1;
  }
  return cells;
}

// Which of formats.md's tables a CSV header is ("" for none), so that a CSV
// given to the wrong option says which table it is.
std::string NameCsvTable(std::string_view header) {
  const std::vector<std::string> cells = HeaderCells(header);
  const auto has = [&](std::string_view c) { return std::find(cells.begin(), cells.end(), c) != cells.end(); };
  const auto has_suffix = [&](std::string_view suffix) {
    return std::any_of(cells.begin(), cells.end(), [&](const std::string& c) {
      return c.size() > suffix.size() && std::string_view(c).substr(c.size() - suffix.size()) == suffix;
    });
  };
  if (has("t_s") && has("axis") && has("K0_mm")) return "the temperature log of docs/formats.md §8.4";
  if (has("t_s") && has_suffix("_count")) return "the encoder counts of docs/formats.md §8.1";
  if (has("axis") && has("run") && has("direction")) return "the ISO 230-2 positioning runs of docs/formats.md §8.6";
  if (has("x_mm") && has("y_mm") && has("z_mm") && has("i") && has("j") && has("k")) {
    return has("t_s") ? "the acquired tool path of docs/formats.md §8.5" : "a programmed tool path (x_mm,y_mm,z_mm,i,j,k)";
  }
  if (has("freq_hz") && has("re") && has("im")) return "the FRF CSV of docs/formats.md §3";
  if (has("case_id") && has("pose_id")) return "the laser-tracker CSV of docs/formats.md §2";
  if (has("pose_id") && has("rope_ux") && has("pulley_x_mm")) {
    return "a load-test plan of kq-identify --plan (for tracker-synth --plan-file)";
  }
  if (has("pose_id") && has("q1_deg")) return "the posture CSV of docs/formats.md §1";
  if (has("hit") && has("force_N")) return "the impact-hammer records of docs/formats.md §10";
  return "";
}

}  // namespace

FileSniff SniffText(std::string_view head) {
  const auto b = [&](size_t i) { return static_cast<unsigned char>(head[i]); };
  if (StartsWith(head, "\x89PNG")) return Kind(FileKind::kPng, "a PNG image");
  if (head.size() >= 3 && b(0) == 0xFF && b(1) == 0xD8 && b(2) == 0xFF) return Kind(FileKind::kJpeg, "a JPEG image");
  if (StartsWith(head, "%PDF")) return Kind(FileKind::kPdf, "a PDF document");
  if (StartsWith(head, "PK\x03\x04")) {
    return Kind(FileKind::kZip, "a ZIP archive (an .xlsx, .ods or .docx is one: export the sheet as CSV)");
  }
  if (head.size() >= 2 && b(0) == 0x1F && b(1) == 0x8B) return Kind(FileKind::kGzip, "a gzip-compressed file (gunzip it first)");
  if (head.size() >= 2 && ((b(0) == 0xFF && b(1) == 0xFE) || (b(0) == 0xFE && b(1) == 0xFF))) {
    return Kind(FileKind::kUtf16, "a UTF-16 text file (save it as UTF-8)");
  }
  // A UFF58 file starts with the "    -1" delimiter in text, also when its
  // records are binary (58b): recognised before the binary scan.
  {
    const size_t start = head.find_first_not_of(" \t\r\n");
    if (start != std::string_view::npos) {
      const size_t end = head.find_first_of("\r\n", start);
      if (Trim(head.substr(start, end == std::string_view::npos ? head.size() - start : end - start)) == "-1") {
        return Kind(FileKind::kUff58, "a UFF58 (Universal File Format) file");
      }
    }
  }
  for (size_t i = 0; i < head.size(); ++i) {
    const unsigned char c = b(i);
    if (c == 0 || (c < 0x20 && c != '\t' && c != '\n' && c != '\r' && c != '\f' && c != '\v')) {
      return Kind(FileKind::kBinary, "a binary file, not text");
    }
  }
  if (StartsWith(head, "\xEF\xBB\xBF")) head.remove_prefix(3);  // UTF-8 BOM
  // The first line that is neither blank nor a comment decides.
  size_t pos = 0;
  bool first_line = true;
  while (pos < head.size()) {
    size_t nl = head.find('\n', pos);
    const bool complete = nl != std::string_view::npos;
    if (!complete) nl = head.size();
    std::string_view raw = head.substr(pos, nl - pos);
    pos = nl + 1;
    if (!raw.empty() && raw.back() == '\r') raw.remove_suffix(1);
    if (first_line && raw.size() >= 73 && raw[72] == 'S' && raw.size() <= 82) {
      return Kind(FileKind::kIges, "an IGES file");
    }
    first_line = false;
    const std::string line = Trim(raw);
    if (line.empty()) continue;
    if (StartsWith(line, "ISO-10303-21")) return Kind(FileKind::kStep, "a STEP file");
    if (line == "-1") return Kind(FileKind::kUff58, "a UFF58 (Universal File Format) file");
    if (line[0] == '<') return Kind(FileKind::kXml, "an XML file (a URDF?)");
    if (LooksLikeMpfLine(line)) {
      return Kind(FileKind::kMpf, "a Siemens MPF file (a part program or table archive of the control)");
    }
    // Comments: '#' (CSV, YAML), ';' (a Siemens part program); '%' also
    // starts a YAML directive.
    if (line[0] == '#' || line[0] == '%' || line[0] == ';') continue;  // comments (both formats), YAML directives
    if (line == "---" || StartsWith(line, "--- ") || line == "-" || StartsWith(line, "- ") || line[0] == '{' ||
        line[0] == '[' || LooksLikeYamlKey(line)) {
      return Kind(FileKind::kYaml, "a YAML file");
    }
    if (line.find(',') != std::string::npos) {
      FileSniff csv = Kind(FileKind::kCsv, "a CSV table");
      csv.table = NameCsvTable(line);
      return csv;
    }
    return Kind(FileKind::kText, "a text file");
  }
  return Kind(FileKind::kEmpty, "an empty file");
}

FileSniff SniffFileKind(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  if (!fs::exists(path, ec)) return Kind(FileKind::kMissing, "no such file");
  if (fs::is_directory(path, ec)) return Kind(FileKind::kMissing, "a folder, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in) return Kind(FileKind::kMissing, "a file that cannot be read");
  std::string head(4096, '\0');
  in.read(head.data(), static_cast<std::streamsize>(head.size()));
  head.resize(static_cast<size_t>(in.gcount()));
  // A multi-byte character cut at the end of the 4 KiB is still text.
  return SniffText(head);
}

std::string WrongFileKindMessage(const FileSniff& got, const std::string& expected, const std::string& option) {
  return "this is " + got.description + "; " + (option.empty() ? "expected " : option + " expects ") + expected +
         (got.table.empty() ? "" : " (its columns are those of " + got.table + ")");
}

void RequireBinaryFile(const std::string& path, const std::string& expected, const std::string& option) {
  const FileSniff s = SniffFileKind(path);
  if (s.kind == FileKind::kMissing) {
    throw MissingFileError({path, 0, 0},
                           "cannot open file for reading: " + s.description + (option.empty() ? "" : " (" + option + ")"));
  }
  if (s.kind == FileKind::kBinary) return;
  std::error_code ec;
  if (s.kind == FileKind::kEmpty && std::filesystem::file_size(path, ec) == 0 && !ec) return;
  // Text read as 16-bit words decodes to noise; name what it is instead.
  FileSniff named = s;
  if (s.kind == FileKind::kEmpty) named.description = "a text file of white space only";
  if (s.kind == FileKind::kText) named.description = "a text file, not binary";
  throw InputError({path, 0, 0}, WrongFileKindMessage(named, expected, option));
}

void RequireFileKind(const std::string& path, std::initializer_list<FileKind> accepted, const std::string& expected,
                     const std::string& option) {
  const FileSniff s = SniffFileKind(path);
  if (s.kind == FileKind::kMissing) {
    throw MissingFileError({path, 0, 0},
                           "cannot open file for reading: " + s.description + (option.empty() ? "" : " (" + option + ")"));
  }
  if (s.kind == FileKind::kEmpty || s.kind == FileKind::kText) return;
  if (std::find(accepted.begin(), accepted.end(), s.kind) != accepted.end()) return;
  throw InputError({path, 0, 0}, WrongFileKindMessage(s, expected, option));
}

}  // namespace robomach::io
