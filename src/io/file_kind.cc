#include "robomach/io/file_kind.h"

#include <algorithm>
#include <filesystem>
#include <fstream>

#include "text.h"

namespace robomach::io {
namespace {

bool StartsWith(std::string_view s, std::string_view prefix) { return s.substr(0, prefix.size()) == prefix; }

FileSniff Kind(FileKind k, std::string description) { return {k, std::move(description)}; }

// A YAML mapping line: "key:" or "key: value", the key without commas.
bool LooksLikeYamlKey(std::string_view line) {
  for (size_t i = 0; i < line.size(); ++i) {
    const char c = line[i];
    if (c == ',' || c == '"' || c == '\'') return false;
    if (c == ':') return i > 0 && (i + 1 == line.size() || line[i + 1] == ' ' || line[i + 1] == '\t');
  }
  return false;
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
    return Kind(FileKind::kBinary, "a UTF-16 text file (save it as UTF-8)");
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
    if (line[0] == '#' || line[0] == '%') continue;  // comments (both formats), YAML directives
    if (line == "---" || StartsWith(line, "--- ") || line == "-" || StartsWith(line, "- ") || line[0] == '{' ||
        line[0] == '[' || LooksLikeYamlKey(line)) {
      return Kind(FileKind::kYaml, "a YAML file");
    }
    if (line.find(',') != std::string::npos) return Kind(FileKind::kCsv, "a CSV table");
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
  return "this is " + got.description + "; " + (option.empty() ? "expected " : option + " expects ") + expected;
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
