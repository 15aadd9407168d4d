#include "robomach/common/closest_name.h"

#include <algorithm>
#include <cctype>
#include <limits>

namespace robomach {

size_t EditDistance(const std::string& a, const std::string& b) {
  std::vector<std::vector<size_t>> d(a.size() + 1, std::vector<size_t>(b.size() + 1, 0));
  for (size_t i = 0; i <= a.size(); ++i) d[i][0] = i;
  for (size_t j = 0; j <= b.size(); ++j) d[0][j] = j;
  for (size_t i = 1; i <= a.size(); ++i) {
    for (size_t j = 1; j <= b.size(); ++j) {
      const size_t sub = a[i - 1] == b[j - 1] ? 0 : 1;
      d[i][j] = std::min({d[i - 1][j] + 1, d[i][j - 1] + 1, d[i - 1][j - 1] + sub});
      if (i > 1 && j > 1 && a[i - 1] == b[j - 2] && a[i - 2] == b[j - 1]) {
        d[i][j] = std::min(d[i][j], d[i - 2][j - 2] + 1);
      }
    }
  }
  return d[a.size()][b.size()];
}

namespace {

std::string Folded(std::string s) {
  for (char& c : s) c = c == '_' ? '-' : static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// The name without its last '-'-separated part ("fmax-hz" -> "fmax").
std::string Stem(const std::string& folded) {
  const size_t dash = folded.rfind('-');
  return dash == std::string::npos || dash == 0 ? folded : folded.substr(0, dash);
}

}  // namespace

std::string ClosestName(const std::string& given, const std::vector<std::string>& known) {
  const std::string g = Folded(given);
  if (g.empty()) return "";
  std::string best;
  size_t best_d = std::numeric_limits<size_t>::max();
  size_t best_raw = best_d;
  for (const std::string& candidate : known) {
    const std::string c = Folded(candidate);
    const size_t raw = EditDistance(g, c);
    const bool same_stem = Stem(g) == Stem(c) || g == Stem(c) || c == Stem(g);
    const size_t d = raw > 0 && same_stem ? 1 : raw;
    if (d < best_d || (d == best_d && raw < best_raw)) {
      best_d = d;
      best_raw = raw;
      best = candidate;
    }
  }
  if (best_d > std::max<size_t>(2, g.size() / 4)) return "";
  return best;
}

}  // namespace robomach
