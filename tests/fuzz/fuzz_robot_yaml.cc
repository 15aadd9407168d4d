// libFuzzer target (issue #22 item 4): the robot config YAML reader
// (docs/formats.md §1). Bad input must be an InputError with a location;
// any other exception, crash, leak or UB report is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "robomach/common/errors.h"
#include "robomach/io/robot_config.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = robomach::fuzz::WriteInput(data, size, ".yaml");
  try {
    const robomach::io::RobotConfig cfg = robomach::io::LoadRobotConfig(path);
    // The model's sense checks of what the reader accepted (the tools run
    // both: workflows::LoadRobotConfigChecked).
    robomach::dynamics::JointPlausibilityFindings(cfg.description, cfg.parameters, cfg.joint_value_locations);
  } catch (const robomach::InputError& e) {
    robomach::fuzz::Rejected(e);
  }
  return 0;
}
