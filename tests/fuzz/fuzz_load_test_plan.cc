// libFuzzer target (issue #22 item 4): the load-test plan CSV read back by
// tracker-synth --plan (io::ReadLoadTestPlanCsv; the file kq-identify --plan
// writes). Bad input must be an InputError with a location; any other
// exception, a crash, a leak, a UB report or a hang is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "robomach/common/errors.h"
#include "robomach/io/kq_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = robomach::fuzz::WriteInput(data, size, ".csv");
  try {
    robomach::io::ReadLoadTestPlanCsv(path, 6);
  } catch (const robomach::InputError& e) {
    robomach::fuzz::Rejected(e);
  }
  return 0;
}
