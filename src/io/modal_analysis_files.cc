#include "robomach/io/modal_analysis_files.h"

#include <cmath>
#include <sstream>

#include "robomach/common/frames.h"
#include "robomach/io/frf_quantity.h"
#include "robomach/io/number_format.h"

namespace robomach::io {
namespace {

nlohmann::json NumberOrNull(double v) { return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(); }

std::string Dir(const dynamics::FrfKey& k) { return std::string(1, AxisName(k.response)) + AxisName(k.excitation); }

}  // namespace

std::string ModalTableCsv(const std::vector<calibration::PoseModes>& poses) {
  std::ostringstream os;
  os << "pose_id,mode,freq_hz,damping_ratio,modal_mass_kg,ux,uy,uz,directions\n";
  for (const calibration::PoseModes& p : poses) {
    int n = 0;
    for (const calibration::TipMode& t : p.tip_modes) {
      if (!std::isfinite(t.modal_mass_kg)) continue;
      os << p.pose_id << ',' << ++n << ',' << FormatDouble(t.freq_hz) << ',' << FormatDouble(t.damping_ratio) << ','
         << FormatDouble(t.modal_mass_kg) << ',' << FormatDouble(t.shape(0)) << ',' << FormatDouble(t.shape(1)) << ','
         << FormatDouble(t.shape(2)) << ',' << t.directions << '\n';
    }
  }
  return os.str();
}

std::string ModalConstantsCsv(const std::vector<calibration::PoseModes>& poses) {
  std::ostringstream os;
  os << "pose_id,fit,mode,freq_hz,damping_ratio,response,excitation,modal_constant_re,modal_constant_im,"
        "peak_contribution_m_per_N,shape_re,shape_im,response_point,excitation_point\n";
  for (const calibration::PoseModes& p : poses) {
    for (size_t g = 0; g < p.groups.size(); ++g) {
      const calibration::ModalGroup& grp = p.groups[g];
      if (grp.fit.status != SolverStatus::kConverged) continue;
      const Eigen::MatrixXcd shapes = grp.fit.ModeShapes();
      for (size_t r = 0; r < grp.fit.modes.size(); ++r) {
        for (size_t i = 0; i < grp.keys.size(); ++i) {
          const calibration::FittedMode& m = grp.fit.per_frf[i].modes[r];
          os << p.pose_id << ',' << g + 1 << ',' << r + 1 << ',' << FormatDouble(m.freq_hz) << ','
             << FormatDouble(m.damping_ratio) << ',' << AxisName(grp.keys[i].response) << ','
             << AxisName(grp.keys[i].excitation) << ',' << FormatDouble(m.modal_constant.real()) << ','
             << FormatDouble(m.modal_constant.imag()) << ',' << FormatDouble(m.peak_contribution) << ','
             << FormatDouble(shapes(i, r).real()) << ',' << FormatDouble(shapes(i, r).imag()) << ','
             << grp.keys[i].response_point << ',' << grp.keys[i].excitation_point << '\n';
        }
      }
    }
  }
  return os.str();
}

std::string ModeShapesCsv(const std::vector<calibration::PoseModes>& poses,
                          const std::vector<calibration::FitRovingShapes>& shapes) {
  std::ostringstream os;
  os << "pose_id,fit,mode,freq_hz,damping_ratio,point,direction,shape_re,shape_im,shape_unit,roving,fixed_point,"
        "fixed_direction\n";
  for (const calibration::FitRovingShapes& f : shapes) {
    const calibration::PoseModes& p = poses.at(f.pose);
    const calibration::ModalGroup& grp = p.groups.at(f.fit);
    const calibration::RovingShapes& rs = f.shapes;
    for (size_t r = 0; r < grp.fit.modes.size(); ++r) {
      for (size_t i = 0; i < rs.points.size(); ++i) {
        os << p.pose_id << ',' << f.fit + 1 << ',' << r + 1 << ',' << FormatDouble(grp.fit.modes[r].freq_hz) << ','
           << FormatDouble(grp.fit.modes[r].damping_ratio) << ',' << rs.points[i] << ','
           << AxisName(rs.directions[i]) << ',' << FormatDouble(rs.shapes(i, r).real()) << ','
           << FormatDouble(rs.shapes(i, r).imag()) << ',' << (rs.mass_normalised ? "1/sqrt(kg)" : "1") << ','
           << rs.roving << ',' << rs.fixed_point << ',' << AxisName(rs.fixed_direction) << '\n';
      }
    }
  }
  return os.str();
}

nlohmann::json ModalAnalysisSummaryJson(const std::vector<calibration::PoseModes>& poses,
                                        const std::string& quantity) {
  using nlohmann::json;
  json j;
  j["quantity"] = quantity;
  j["postures"] = json::array();
  for (const calibration::PoseModes& p : poses) {
    json jp;
    jp["pose_id"] = p.pose_id;
    jp["fits"] = json::array();
    for (const calibration::ModalGroup& g : p.groups) {
      json jg;
      jg["frfs"] = json::array();
      for (size_t i = 0; i < g.keys.size(); ++i) {
        json jf;
        jf["frf"] = Dir(g.keys[i]);
        if (g.keys[i].response_point != 0 || g.keys[i].excitation_point != 0) {
          jf["response_point"] = g.keys[i].response_point;
          jf["excitation_point"] = g.keys[i].excitation_point;
        }
        jf["lines"] = g.data[i].size();
        jf["misfit_relative"] = NumberOrNull(i < g.misfit.size() ? g.misfit[i] : NAN);
        jf["misfit_noise_sigmas"] =
            NumberOrNull(i < g.fit.misfit_in_noise.size() ? g.fit.misfit_in_noise[i] : NAN);
        jf["misfit_noise_sigmas_noise_weights"] = NumberOrNull(
            i < g.fit.misfit_in_noise_weights_alone.size() ? g.fit.misfit_in_noise_weights_alone[i] : NAN);
        // τ in the file's quantity (the summary's `quantity`), its unit beside it.
        jf["model_error_rms"] = i < g.fit.model_error.size() ? g.fit.model_error[i] : 0.0;
        for (FrfQuantity q : {FrfQuantity::kReceptance, FrfQuantity::kMobility, FrfQuantity::kAccelerance}) {
          if (ToString(q) == quantity) jf["model_error_unit"] = QuantityUnit(q);
        }
        jg["frfs"].push_back(jf);
      }
      jg["status"] = robomach::ToString(g.fit.status);
      jg["message"] = g.fit.message;
      jg["fmin_hz"] = g.fit.fmin_hz;
      jg["fmax_hz"] = g.fit.fmax_hz;
      jg["orders_tried"] = g.fit.orders_tried;
      jg["lscf_power"] = g.fit.lscf_power;
      jg["modes"] = json::array();
      for (const calibration::GlobalMode& m : g.fit.modes) {
        jg["modes"].push_back(
            {{"freq_hz", m.freq_hz}, {"damping_ratio", m.damping_ratio}, {"stable_orders", m.stable_orders}});
      }
      jp["fits"].push_back(jg);
    }
    jp["tip_modes"] = json::array();
    for (const calibration::TipMode& t : p.tip_modes) {
      jp["tip_modes"].push_back({{"freq_hz", t.freq_hz},
                                 {"damping_ratio", t.damping_ratio},
                                 {"modal_mass_kg", NumberOrNull(t.modal_mass_kg)},
                                 {"shape", {t.shape(0), t.shape(1), t.shape(2)}},
                                 {"directions", t.directions}});
    }
    jp["warnings"] = p.warnings;
    j["postures"].push_back(jp);
  }
  return j;
}

}  // namespace robomach::io
