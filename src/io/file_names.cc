#include "robomach/io/file_names.h"

#include <algorithm>
#include <cctype>
#include <set>

namespace robomach::io {
namespace {

constexpr size_t kMaxStemLength = 100;  // well below NAME_MAX (255) with a prefix and ".png"

bool SafeChar(char c) {
  return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z') || (c >= '0' && c <= '9') || c == '.' || c == '_' ||
         c == '-';
}

std::string Sanitise(const std::string& id) {
  std::string s;
  s.reserve(std::min(id.size(), kMaxStemLength));
  for (size_t i = 0; i < id.size() && s.size() < kMaxStemLength; ++i) {
    char c = id[i];
    if (!SafeChar(c)) c = '_';
    if (c == '.' && (i == 0 || id[i - 1] == '.')) c = '_';
    s.push_back(c);
  }
  if (s.empty()) s = "_";
  return s;
}

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

}  // namespace

std::map<std::string, std::string> SafeFileStems(const std::vector<std::string>& ids) {
  const std::set<std::string> sorted(ids.begin(), ids.end());
  std::map<std::string, std::string> stems;
  std::set<std::string> taken;  // lower case
  auto assign = [&](const std::string& id, const std::string& base) {
    std::string stem = base;
    for (int k = 2; taken.contains(Lower(stem)); ++k) stem = base + "_" + std::to_string(k);
    taken.insert(Lower(stem));
    stems[id] = stem;
  };
  // IDs that are file names already keep them; the others follow.
  for (const std::string& id : sorted) {
    if (Sanitise(id) == id) assign(id, id);
  }
  for (const std::string& id : sorted) {
    if (!stems.contains(id)) assign(id, Sanitise(id));
  }
  return stems;
}

}  // namespace robomach::io
