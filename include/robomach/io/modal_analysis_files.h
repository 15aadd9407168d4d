#pragma once

// frf-modes' outputs (formats.md §4.2): the modal table (formats.md §4, the
// table stability-lobes --modal-table reads, with the fit's own columns
// after it), the modal constants of every FRF (the mode shapes), and the
// JSON summary.

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "robomach/calibration/modal_analysis.h"

namespace robomach::io {

/// `pose_id,mode,freq_hz,damping_ratio,modal_mass_kg,ux,uy,uz,directions,
/// stable_orders`: the tool-tip modes with a modal mass, per posture.
std::string ModalTableCsv(const std::vector<calibration::PoseModes>& poses);

/// `pose_id,fit,mode,freq_hz,damping_ratio,response,excitation,
/// modal_constant_re,modal_constant_im,peak_contribution_m_per_N,
/// shape_re,shape_im`: one row per mode and FRF. The modal constant A
/// [m/N·(rad/s)²] of H = Σ A/(ω_n² − ω² + 2iζω_nω); the shape is A scaled so
/// that the largest of the fit's FRFs is 1 (the mode shape over the FRFs).
std::string ModalConstantsCsv(const std::vector<calibration::PoseModes>& poses);

/// `pose_id,fit,mode,freq_hz,damping_ratio,point,direction,shape_re,
/// shape_im,shape_unit,roving,fixed_point,fixed_direction`: the mode shapes
/// `shapes` of the fits of `poses` that are roving tests (computed by the
/// caller: calibration::ShapesOfRovingTests, which notes the fits that are
/// none), one row per mode and point, in the order of `shapes`; shape_unit
/// `1/sqrt(kg)` (mass-normalised, the test has a driving point) or `1`
/// (largest component 1).
std::string ModeShapesCsv(const std::vector<calibration::PoseModes>& poses,
                          const std::vector<calibration::FitRovingShapes>& shapes);

/// The summary (formats.md §4.2).
nlohmann::json ModalAnalysisSummaryJson(const std::vector<calibration::PoseModes>& poses,
                                        const std::string& quantity);

}  // namespace robomach::io
