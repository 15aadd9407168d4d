#include "robomach/io/program_file.h"

#include "robomach/common/errors.h"
#include "robomach/common/units.h"
#include "robomach/io/csv_table.h"

namespace robomach::io {

machine::ProgrammedPath ReadProgramFile(const std::string& path) {
  const CsvTable t = CsvTable::ReadFile(path);
  for (const char* c : {"x_mm", "y_mm", "z_mm", "i", "j", "k"}) t.RequireColumn(c);
  std::vector<Eigen::Vector3d> tips, axes;
  for (int r = 0; r < t.num_rows(); ++r) {
    tips.emplace_back(MmToM(t.Number(r, "x_mm")), MmToM(t.Number(r, "y_mm")), MmToM(t.Number(r, "z_mm")));
    const Eigen::Vector3d k(t.Number(r, "i"), t.Number(r, "j"), t.Number(r, "k"));
    if (!(k.norm() > 1e-9)) throw t.ErrorAt(r, "i", "the tool axis (i, j, k) is zero");
    axes.push_back(k);
  }
  if (tips.size() < 2) throw InputError({path, t.header_line(), 0}, "expected at least 2 points of the path");
  return AtLocation({path, 0, 0}, "", [&] { return machine::ProgrammedPath(tips, axes); });
}

}  // namespace robomach::io
