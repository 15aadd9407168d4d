#include "robomach/io/frf_files.h"

#include <algorithm>

#include "robomach/common/number_format.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/io/file_kind.h"
#include "robomach/io/uff58.h"
#include "frf_text.h"

#include "text.h"


namespace robomach::io {

FrfReadResult ReadFrfFile(const std::string& path, const std::string& default_pose_id, bool keep_points) {
  std::string ext;
  if (auto dot = path.find_last_of('.'); dot != std::string::npos) ext = Lower(path.substr(dot + 1));
  // A YAML config, a picture or a spreadsheet is named before either parser
  // sees it (io/file_kind.h).
  RequireFileKind(path, {FileKind::kCsv, FileKind::kUff58}, kFrfFileFormat);
  if (ext == "uff" || ext == "unv" || ext == "uf" || ext == "ufb" || LooksLikeUff(path)) {
    FrfReadResult r = ReadUff58(path, default_pose_id, keep_points);
    r.file_format = dynamics::FrfFileFormat::kUff58;
    return r;
  }
  FrfReadResult r = ReadFrfCsv(path, keep_points);
  r.file_format = dynamics::FrfFileFormat::kCsv;
  return r;
}

std::vector<std::string> FrequencyUnitFindings(const FrfReadResult& read, const std::string& path) {
  double top = 0.0;
  for (const auto& [key, frf] : read.frfs) {
    if (frf.size() > 0) top = std::max(top, frf.freq_hz().maxCoeff());
  }
  if (read.frfs.empty()) return {};
  const std::string f = dynamics::FrequencyAxisFinding(path, top, read.file_format);
  if (f.empty()) return {};
  return {f};
}

}  // namespace robomach::io
