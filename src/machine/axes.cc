#include "robomach/machine/axes.h"

namespace robomach::machine {

int FindAxis(const std::vector<AxisScale>& axes, const std::string& name) {
  for (size_t i = 0; i < axes.size(); ++i) {
    if (axes[i].name == name) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace robomach::machine
