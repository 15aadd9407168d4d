#pragma once

// What kind of file a reader was given, recognised from its first bytes
// before any parsing (issue #35): a YAML config given as a posture CSV, a
// UFF58 file given as the tracker CSV, a PNG given as the robot config are
// named as such ("this is a YAML file; --postures expects the posture CSV of
// docs/formats.md §1") instead of failing on some line of the wrong parser.

#include <initializer_list>
#include <string>
#include <string_view>

#include "robomach/common/errors.h"

namespace robomach::io {

enum class FileKind {
  kMissing,    // no such file, a folder, or not readable
  kEmpty,      // no bytes, or only white space
  kText,       // text of no kind recognised below (never refused)
  kCsv,        // first line that is not a comment holds commas, not "key:"
  kYaml,       // "key:", "---" or "- item" first
  kUff58,      // "    -1" first (Universal File Format)
  kXml,        // "<" first (a URDF)
  kIges,       // 80-column lines with the section letter in column 73
  kStep,       // "ISO-10303-21;"
  kMpf,        // Siemens part program / archive: "%_N_...", "$NAME[...]=", "CHANDATA(" first
  kPng,
  kJpeg,
  kPdf,
  kZip,        // also .xlsx, .docx, .ods
  kGzip,
  kBinary,     // NUL or other control bytes
  kUtf16,      // a UTF-16 byte order mark: text, but not UTF-8
};

struct FileSniff {
  FileKind kind{FileKind::kText};
  /// "a YAML file", "a UFF58 file", "a PNG image", ... for messages.
  std::string description;
  /// For a CSV whose header is one of docs/formats.md's tables, which one:
  /// "the temperature log of docs/formats.md §8.4"; else empty.
  std::string table;
};

/// Recognises a file from its first 4 KiB.
FileSniff SniffFileKind(const std::string& path);
/// The same for text already read (the first bytes of a file).
FileSniff SniffText(std::string_view head);

/// A file an input names (on the command line or inside a config) that does
/// not exist or cannot be read. The tools exit 66 for it (docs/conventions.md).
class MissingFileError : public InputError {
 public:
  using InputError::InputError;
};

/// "this is a YAML file; --postures expects the posture CSV of
/// docs/formats.md §1" (without `option`: "...; expected the posture CSV
/// ..."). `expected` names the format and where it is documented. A CSV of
/// a known table ends with "(its columns are those of <table>)".
std::string WrongFileKindMessage(const FileSniff& got, const std::string& expected,
                                 const std::string& option = "");

/// Checks a file that must be binary (a raw capture, formats.md §8.2)
/// before it is read: text of any kind (a CSV given as the capture), UTF-16
/// text and every recognised kind (PNG, PDF, ZIP, gzip, UFF58, ...) are
/// refused. An empty file is passed on (the reader says it is empty).
/// @throws MissingFileError as RequireFileKind; InputError
///   (WrongFileKindMessage) for a file that is not unrecognised binary.
void RequireBinaryFile(const std::string& path, const std::string& expected, const std::string& option = "");

/// Checks `path` before a reader parses it.
/// @throws MissingFileError if it does not exist, is a folder or cannot be
///   read; InputError (WrongFileKindMessage) if it is recognised as a kind
///   not in `accepted`. Empty files and unrecognised text are passed on to
///   the reader, whose own messages say what is wrong.
void RequireFileKind(const std::string& path, std::initializer_list<FileKind> accepted,
                     const std::string& expected, const std::string& option = "");

// What the readers expect, for WrongFileKindMessage.
inline constexpr char kPostureCsvFormat[] = "the posture CSV of docs/formats.md §1";
inline constexpr char kTrackerCsvFormat[] = "the laser-tracker CSV of docs/formats.md §2";
inline constexpr char kFrfFileFormat[] = "an FRF CSV or UFF58 file of docs/formats.md §3";
inline constexpr char kRobotConfigFormat[] = "a robot config YAML (as config/kr210.yaml)";
inline constexpr char kCutFileFormat[] = "a cut YAML of docs/stability.md (as config/cut_demo.yaml)";
inline constexpr char kCsvTableFormat[] = "a CSV table of docs/formats.md";
inline constexpr char kYamlFileFormat[] = "a YAML file";
inline constexpr char kCompensationFileFormat[] =
    "the Siemens compensation tables ($AA_ENC_COMP, $AN_CEC assignments) of docs/formats.md §8.4";
inline constexpr char kTemperatureLogFormat[] =
    "the temperature log CSV t_s,axis,K0_mm,tan_beta,P0_mm of docs/formats.md §8.4";
inline constexpr char kCaptureFileFormat[] =
    "the raw binary capture (little-endian uint16 words) of docs/formats.md §8.2";

}  // namespace robomach::io
