#include "robomach/io/urdf_loader.h"

#include <algorithm>
#include <cctype>
#include <cstdio>
#include <fstream>
#include <set>
#include <sstream>
#include <vector>

#include <console_bridge/console.h>
#include <urdf_parser/urdf_parser.h>

#include "robomach/common/errors.h"
#include "robomach/io/file_kind.h"

namespace robomach::io {
namespace {

// urdfdom reports its reasons only through console_bridge (style.md §3):
// capture them while parsing so the InputError can say what was wrong.
class CaptureConsoleBridge final : public console_bridge::OutputHandler {
 public:
  CaptureConsoleBridge() { console_bridge::useOutputHandler(this); }
  ~CaptureConsoleBridge() override { console_bridge::restorePreviousOutputHandler(); }
  void log(const std::string& text, console_bridge::LogLevel level, const char*, int) override {
    if (level >= console_bridge::CONSOLE_BRIDGE_LOG_WARN) messages.push_back(text);
  }
  std::vector<std::string> messages;
};

// Line and column (1-based) of the first whitespace-separated token inside a
// quoted attribute value that equals `token` (or, with `token` empty, that
// reads as NaN or inf: "nan", "-inf", "Infinity"...), and the token; line 0
// if there is none.
SourceLocation LocateAttributeToken(const std::string& xml, const std::string& path, const std::string& token,
                                    std::string* found = nullptr) {
  bool in_value = false;
  char quote = 0;
  int line = 1, col = 0;
  for (size_t i = 0; i < xml.size(); ++i) {
    const char c = xml[i];
    ++col;
    if (c == '\n') {
      ++line;
      col = 0;
      continue;
    }
    if (!in_value) {
      if ((c == '"' || c == '\'') && i > 0 && xml[i - 1] == '=') {
        in_value = true;
        quote = c;
      }
      continue;
    }
    if (c == quote) {
      in_value = false;
      continue;
    }
    const bool starts = xml[i - 1] == quote || xml[i - 1] == ' ' || xml[i - 1] == '\t';
    if (!starts || c == ' ' || c == '\t') continue;
    size_t e = i;
    while (e < xml.size() && xml[e] != quote && xml[e] != ' ' && xml[e] != '\t' && xml[e] != '\n') ++e;
    std::string t = xml.substr(i, e - i);
    bool match = t == token;
    if (token.empty()) {
      std::string low = t;
      for (char& ch : low) ch = static_cast<char>(std::tolower(static_cast<unsigned char>(ch)));
      if (!low.empty() && (low[0] == '+' || low[0] == '-')) low.erase(0, 1);
      match = low.rfind("nan", 0) == 0 || low.rfind("inf", 0) == 0;
    }
    if (match) {
      if (found) *found = t;
      return {path, line, col};
    }
  }
  return {path, 0, 0};
}

// 1-based line of the first `<tag ... name="name"`, 0 if not found.
int FindElementLine(const std::string& xml, const std::string& tag, const std::string& name) {
  const std::string needle = "name=\"" + name + "\"";
  size_t pos = 0;
  while ((pos = xml.find("<" + tag, pos)) != std::string::npos) {
    const size_t end = xml.find('>', pos);
    if (end != std::string::npos && xml.substr(pos, end - pos).find(needle) != std::string::npos) {
      return 1 + static_cast<int>(std::count(xml.begin(), xml.begin() + pos, '\n'));
    }
    ++pos;
  }
  return 0;
}

KDL::Vector ToKdl(const urdf::Vector3& v) { return KDL::Vector(v.x, v.y, v.z); }
KDL::Rotation ToKdl(const urdf::Rotation& r) { return KDL::Rotation::Quaternion(r.x, r.y, r.z, r.w); }
KDL::Frame ToKdl(const urdf::Pose& p) { return KDL::Frame(ToKdl(p.rotation), ToKdl(p.position)); }

// The URDF file being loaded: its path and its text, which every stage
// needs for the file:line:column of its messages.
struct UrdfSource {
  const std::string& path;
  const std::string& xml;
};

// Valid UTF-8 only: TinyXML (urdfdom's parser) skips a multi-byte
// sequence by its lead byte's length, and a lead byte cut off at the end
// of the file made it read past the buffer (heap-buffer-overflow in
// TiXmlBase::ReadName; issue #22, found by fuzz_urdf).
void CheckUtf8(const UrdfSource& src) {
  const std::string& path = src.path;
  const std::string& xml = src.xml;
  int line = 1, column = 1;
  for (size_t i = 0; i < xml.size();) {
    const unsigned char c = static_cast<unsigned char>(xml[i]);
    const int n = c < 0x80 ? 1 : (c >> 5) == 0x6 ? 2 : (c >> 4) == 0xE ? 3 : (c >> 3) == 0x1E ? 4 : 0;
    bool ok = n > 0 && i + n <= xml.size() && !(n == 2 && c < 0xC2);
    for (int k = 1; ok && k < n; ++k) ok = (static_cast<unsigned char>(xml[i + k]) & 0xC0) == 0x80;
    if (!ok) {
      char hex[8];
      std::snprintf(hex, sizeof(hex), "0x%02X", c);
      throw InputError({path, line, column},
                       std::string("not valid UTF-8 (byte ") + hex + "); a URDF is UTF-8 XML");
    }
    if (c == '\n') {
      ++line;
      column = 1;
    } else {
      ++column;
    }
    i += n;
  }
}

// NaN and inf: urdfdom reads some of them as numbers (an inertial origin
// of "nan" passes), so every attribute value is checked first.
void CheckFiniteAttributes(const UrdfSource& src) {
  std::string token;
  const SourceLocation at = LocateAttributeToken(src.xml, src.path, "", &token);
  if (at.line > 0) throw InputError(at, "expected a finite number, got \"" + token + "\"");
}

// The urdfdom model of the text; a text urdfdom refuses is an InputError
// with urdfdom's reasons, captured from console_bridge.
urdf::ModelInterfaceSharedPtr ParseModel(const UrdfSource& src) {
  const std::string& path = src.path;
  const std::string& xml = src.xml;
  CaptureConsoleBridge capture;
  urdf::ModelInterfaceSharedPtr model = urdf::parseURDF(xml);
  if (!model) {
    std::string reason;
    for (const auto& m : capture.messages) reason += (reason.empty() ? "" : "; ") + m;
    if (reason.empty()) reason = "urdfdom gave no reason";
    // urdfdom names a number it could not parse ("Unable to parse
    // component [nan] to a double") but not where: the first attribute
    // value holding that token gives the line and column.
    SourceLocation at{path, 0, 0};
    const std::string key = "Unable to parse component [";
    if (const size_t k = reason.find(key); k != std::string::npos) {
      const size_t e = reason.find(']', k + key.size());
      if (e != std::string::npos) at = LocateAttributeToken(xml, path, reason.substr(k + key.size(), e - k - key.size()));
    }
    throw InputError(at, "not a valid URDF model: " + reason);
  }
  return model;
}

// urdfdom's links own their children (shared_ptr), and urdfdom accepts a
// joint cycle, which then owns itself and leaks (issue #22, fuzz_urdf).
// Everything needed is copied out of the model, so LoadUrdfChain takes the
// tree apart on every way out of it.
struct TreeBreaker {
  const urdf::ModelInterfaceSharedPtr& model;
  ~TreeBreaker() {
    for (auto& [name, link] : model->links_) {
      if (!link) continue;
      link->child_links.clear();
      link->child_joints.clear();
    }
  }
};

// Refuses a base or tip link the model does not have, listing its links.
void RequireLink(const UrdfSource& src, const urdf::ModelInterface& model, const std::string& role,
                 const std::string& name) {
  if (model.getLink(name)) return;
  std::string names;
  for (const auto& [n, l] : model.links_) names += (names.empty() ? "" : ", ") + n;
  throw InputError({src.path, 0, 0}, role + " link '" + name + "' is not in the URDF; its links: " + names);
}

// The links from the base down to the tip (walked from the tip up).
std::vector<urdf::LinkConstSharedPtr> LinksBaseToTip(const UrdfSource& src, const urdf::ModelInterface& model,
                                                     const std::string& base_link, const std::string& tip_link) {
  std::vector<urdf::LinkConstSharedPtr> links;
  std::set<std::string> seen;
  for (urdf::LinkConstSharedPtr l = model.getLink(tip_link); l; l = l->getParent()) {
    // urdfdom accepts a joint whose parent is a descendant of its child (a
    // cycle); walking up it never ended (issue #22, found by fuzz_urdf).
    if (!seen.insert(l->name).second) {
      const std::string joint = l->parent_joint ? l->parent_joint->name : "";
      throw InputError({src.path, FindElementLine(src.xml, "joint", joint), 0},
                       "link '" + l->name + "' is its own ancestor: the joints above tip link '" + tip_link +
                           "' form a cycle (expected a tree; check the <parent link> of joint '" + joint + "')");
    }
    links.push_back(l);
    if (l->name == base_link) break;
  }
  if (links.back()->name != base_link) {
    throw InputError({src.path, 0, 0},
                     "tip link '" + tip_link + "' is not below base link '" + base_link + "'");
  }
  std::reverse(links.begin(), links.end());
  return links;
}

// The chain being assembled from the base: its KDL segments and the names
// and limits of its movable joints.
struct ChainParts {
  KDL::Chain chain;
  std::vector<std::string> names;
  std::vector<kinematics::JointLimits> limits;
};

// The KDL joint of a link's parent joint (at `line`, frame F); a movable
// joint's name and limits are added to `parts`.
KDL::Joint ReadJoint(const UrdfSource& src, const urdf::JointConstSharedPtr& j, const KDL::Frame& F, int line,
                     ChainParts* parts) {
  const std::string& path = src.path;
  KDL::Joint joint(j->name, KDL::Joint::None);
  switch (j->type) {
    case urdf::Joint::FIXED:
      break;
    case urdf::Joint::REVOLUTE:
    case urdf::Joint::CONTINUOUS: {
      const KDL::Vector axis = ToKdl(j->axis);
      if (axis.Norm() < 1e-9) throw InputError({path, line, 0}, "joint '" + j->name + "' has a zero axis");
      joint = KDL::Joint(j->name, F.p, F.M * (axis / axis.Norm()), KDL::Joint::RotAxis);
      kinematics::JointLimits lim;
      if (j->type == urdf::Joint::REVOLUTE && j->limits) {
        lim.lower = j->limits->lower;
        lim.upper = j->limits->upper;
        lim.bounded = true;
        if (!(lim.lower < lim.upper)) {
          throw InputError({path, line, 0}, "joint '" + j->name + "': lower limit " +
                                                std::to_string(lim.lower) +
                                                " rad is not below upper limit " +
                                                std::to_string(lim.upper) +
                                                " rad (a <limit> without lower/upper reads as 0/0)");
        }
      }
      parts->names.push_back(j->name);
      parts->limits.push_back(lim);
      break;
    }
    default:
      throw InputError({path, line, 0}, "joint '" + j->name +
                                            "': only revolute, continuous and fixed joints are "
                                            "supported");
  }
  return joint;
}

// A link's inertia about its segment frame (zero without <inertial>),
// refused when it is not physical.
kinematics::Inertial ReadInertial(const UrdfSource& src, const urdf::LinkConstSharedPtr& link) {
  kinematics::Inertial b;
  if (link->inertial) {
    const urdf::Inertial& u = *link->inertial;
    const KDL::Frame Fi = ToKdl(u.origin);
    kinematics::Inertial local;
    local.mass = u.mass;
    local.inertia_com << u.ixx, u.ixy, u.ixz, u.ixy, u.iyy, u.iyz, u.ixz, u.iyz, u.izz;
    Eigen::Isometry3d X = Eigen::Isometry3d::Identity();
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) X.linear()(r, c) = Fi.M(r, c);
      X.translation()(r) = Fi.p(r);
    }
    if (auto problem = kinematics::CheckInertial(local)) {
      throw InputError({src.path, FindElementLine(src.xml, "link", link->name), 0},
                       "link '" + link->name + "': inertial is not physical: " + *problem);
    }
    b = kinematics::TransformInertial(local, X);
  }
  return b;
}

}  // namespace

kinematics::SerialChain LoadUrdfChain(const std::string& path, const std::string& base_link,
                                      const std::string& tip_link) {
  std::ifstream in(path);
  if (!in) throw MissingFileError({path, 0, 0}, "cannot open URDF file for reading");
  std::stringstream ss;
  ss << in.rdbuf();
  const std::string xml = ss.str();
  const UrdfSource src{path, xml};

  CheckUtf8(src);
  CheckFiniteAttributes(src);
  const urdf::ModelInterfaceSharedPtr model = ParseModel(src);
  const TreeBreaker tree_breaker{model};
  RequireLink(src, *model, "base", base_link);
  RequireLink(src, *model, "tip", tip_link);
  const std::vector<urdf::LinkConstSharedPtr> links = LinksBaseToTip(src, *model, base_link, tip_link);

  ChainParts parts;
  for (size_t i = 1; i < links.size(); ++i) {
    const urdf::LinkConstSharedPtr& link = links[i];
    const urdf::JointConstSharedPtr& j = link->parent_joint;
    const int line = FindElementLine(xml, "joint", j->name);
    const KDL::Frame F = ToKdl(j->parent_to_joint_origin_transform);
    const KDL::Joint joint = ReadJoint(src, j, F, line, &parts);
    const kinematics::Inertial b = ReadInertial(src, link);
    parts.chain.addSegment(KDL::Segment(link->name, joint, F, kinematics::ToKdl(b)));
  }
  if (parts.names.empty()) {
    throw InputError({path, 0, 0}, "no movable joint between '" + base_link + "' and '" +
                                       tip_link + "'");
  }
  return kinematics::SerialChain(std::move(parts.chain), std::move(parts.names), std::move(parts.limits), base_link,
                                 tip_link);
}

}  // namespace robomach::io
