#include "robomach/io/drill_series_file.h"

#include <sstream>

#include "robomach/common/units.h"
#include "robomach/io/number_format.h"

namespace robomach::io {

std::string DrillSeriesCsv(const drilling::SimResult& r) {
  const drilling::SimSeries& s = r.series;
  const int n = static_cast<int>(s.q.rows());
  std::ostringstream o;
  o << "t_s";
  for (int i = 1; i <= n; ++i) o << ",q" << i << "_deg";
  for (int i = 1; i <= n; ++i) o << ",e" << i << "_deg";
  for (int i = 1; i <= n; ++i) o << ",tau_m" << i << "_Nm";
  o << ",thrust_N,torque_Nm,offset_deg\n";
  for (size_t k = 0; k < s.t.size(); ++k) {
    o << FormatDouble(s.t[k]);
    for (int i = 0; i < n; ++i) o << "," << FormatDouble(RadToDeg(s.q(i, k)));
    for (int i = 0; i < n; ++i) o << "," << FormatDouble(RadToDeg(s.e(i, k)));
    for (int i = 0; i < n; ++i) o << "," << FormatDouble(s.tau_m(i, k));
    o << "," << FormatDouble(s.thrust[k]) << "," << FormatDouble(s.torque[k]) << "," << FormatDouble(RadToDeg(s.offset[k]))
      << "\n";
  }
  return o.str();
}

}  // namespace robomach::io
