// libFuzzer target (issue #22 item 4): the drilling thrust/torque table
// reader (docs/formats.md §9.1; drill-force-fit), as a table to fit (forces
// required) and as --predict rows (forces optional). Bad input must be an
// InputError with a location; any other exception, a crash, a leak, a UB
// report or a hang is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "robomach/common/errors.h"
#include "robomach/io/drilling_files.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path = robomach::fuzz::WriteInput(data, size, ".csv");
  for (const bool require_forces : {true, false}) {
    try {
      robomach::io::ReadForceTable(path, require_forces);
    } catch (const robomach::InputError& e) {
      robomach::fuzz::Rejected(e);
    }
  }
  return 0;
}
