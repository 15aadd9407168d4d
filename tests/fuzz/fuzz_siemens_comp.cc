// libFuzzer target (issue #22 item 4): the Siemens 840D sl compensation
// tables reader ($AA_ENC_COMP, $AN_CEC; docs/formats.md §8.4), and the
// compensation axis-acquire and axis-synth build from the tables at once.
// Bad input must be an InputError with a location; any other exception, a
// crash, a leak, a UB report or a hang is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "fuzz_machine_context.h"
#include "robomach/common/errors.h"
#include "robomach/machine/compensation.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const robomach::io::MachineFile& mf = robomach::fuzz::DemoMachine();
  const std::string path = robomach::fuzz::WriteInput(data, size, ".mpf");
  try {
    const robomach::io::CompensationTables t = robomach::io::ReadCompensationFile(path, mf);
    const robomach::machine::Compensation comp(static_cast<int>(mf.machine.axes.size()), t.encoder, t.cross_axis, {});
  } catch (const robomach::InputError& e) {
    robomach::fuzz::Rejected(e);
  }
  return 0;
}
