#pragma once
// axis-acquire's inputs read and checked together (docs/formats.md §8): the
// machine file, the encoder counts, and optionally the controller's
// compensation tables, its temperature log and the programmed path.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "robomach/io/compensation_file.h"
#include "robomach/io/machine_file.h"
#include "robomach/machine/acquisition.h"
#include "robomach/machine/compensation.h"
#include "robomach/machine/synthesis.h"

namespace robomach::workflows {

struct AcquisitionInputs {
  io::MachineFile machine;
  io::CompensationTables tables;                                 // empty without a compensation file
  std::vector<machine::TemperatureCompensation> temperatures;  // empty without a temperature log
  std::unique_ptr<machine::Compensation> compensation;       // all of them; empty() when none
  std::optional<machine::ProgrammedPath> program;
  machine::CountsRecord counts;
  /// The temperature log's and the counts file's unit findings.
  std::vector<std::string> temperature_implausible, counts_implausible;
  /// The compensation the acquisition applies (null when there is none).
  const machine::Compensation* applied() const {
    return compensation && !compensation->empty() ? compensation.get() : nullptr;
  }
  /// The unit findings of the machine file, the compensation tables, the
  /// temperature log and the counts (docs/plausibility.md), in that order:
  /// the tool flags its result (exit 3) on any.
  std::vector<std::string> implausible() const {
    std::vector<std::string> all = machine.implausible;
    all.insert(all.end(), tables.implausible.begin(), tables.implausible.end());
    all.insert(all.end(), temperature_implausible.begin(), temperature_implausible.end());
    all.insert(all.end(), counts_implausible.begin(), counts_implausible.end());
    return all;
  }
};

/// Reads every input before any work (an empty path: not given).
/// `compensation_option` names the compensation file in a message about
/// what it is (the tool's "--compensation"; "" for a library caller).
/// @throws InputError naming the file, line and column of the first problem.
AcquisitionInputs ReadAcquisitionInputs(const std::string& machine_path, const std::string& counts_path,
                                        const std::string& compensation_path = "",
                                        const std::string& temperature_path = "",
                                        const std::string& program_path = "",
                                        const std::string& compensation_option = "");

}  // namespace robomach::workflows
