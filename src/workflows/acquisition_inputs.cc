#include "robomach/workflows/acquisition_inputs.h"

#include "robomach/io/counts_file.h"
#include "robomach/io/program_file.h"
#include "robomach/io/temperature_log.h"

namespace robomach::workflows {

AcquisitionInputs ReadAcquisitionInputs(const std::string& machine_path, const std::string& counts_path,
                                        const std::string& compensation_path, const std::string& temperature_path,
                                        const std::string& program_path, const std::string& compensation_option) {
  AcquisitionInputs in;
  in.machine = io::ReadMachineFile(machine_path);
  if (!compensation_path.empty()) in.tables = io::ReadCompensationFile(compensation_path, in.machine, compensation_option);
  if (!temperature_path.empty()) in.temperatures = io::ReadTemperatureLog(temperature_path, in.machine, &in.temperature_implausible);
  in.compensation = std::make_unique<machine::Compensation>(static_cast<int>(in.machine.machine.axes.size()),
                                                            in.tables.encoder, in.tables.cross_axis, in.temperatures);
  if (!program_path.empty()) in.program = io::ReadProgramFile(program_path);
  in.counts = io::ReadCountsFile(counts_path, in.machine, &in.counts_implausible);
  return in;
}

}  // namespace robomach::workflows
