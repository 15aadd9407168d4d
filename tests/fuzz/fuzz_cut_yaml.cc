// libFuzzer target (issue #22 item 4): the milling cut YAML reader (stability tools)
// (config/cut_demo.yaml). Bad input must be an InputError with a location; any other
// exception, a crash, a leak, a UB report or a hang is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "robomach/common/errors.h"
#include "robomach/io/cut_file.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = robomach::fuzz::WriteInput(data, size, ".yaml");
  try {
    robomach::io::ReadCutFile(path);
  } catch (const robomach::InputError& e) {
    robomach::fuzz::Rejected(e);
  }
  return 0;
}
