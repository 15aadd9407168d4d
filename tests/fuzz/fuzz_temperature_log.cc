// libFuzzer target (issue #22 item 4): the temperature log reader
// (t_s,axis,K0_mm,tan_beta,P0_mm; docs/formats.md §8.4). Bad input must be
// an InputError with a location; any other exception, a crash, a leak, a UB
// report or a hang is a finding.
#include <cstddef>
#include <cstdint>

#include "fuzz_input_file.h"
#include "fuzz_machine_context.h"
#include "robomach/common/errors.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const robomach::io::MachineFile& mf = robomach::fuzz::DemoMachine();
  const std::string path = robomach::fuzz::WriteInput(data, size, ".csv");
  try {
    robomach::io::ReadTemperatureLog(path, mf);
  } catch (const robomach::InputError& e) {
    robomach::fuzz::Rejected(e);
  }
  return 0;
}
