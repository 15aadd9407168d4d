#pragma once

// A measured FRF with its modal fit, for people to judge the fit (issue #18):
// the measured lines the fit used, the lines it left out (below the noise
// model's signal-to-noise limit: the drift and the floor), the fitted modal
// model, the noise floor, the usable band and the fitted modes.

#include <string>

#include "robomach/calibration/frf_noise.h"
#include "robomach/calibration/modal_fit.h"
#include "robomach/dynamics/measured_frf.h"
#include "robomach/report/plot.h"

namespace robomach::report {

/// Fills a magnitude panel (log |H| [m/N]) and a phase panel [deg]; the
/// frequency axis is logarithmic when the FRF spans more than two decades.
/// The edges of each usable stretch and each fitted mode are marked (where
/// the labels cannot all be placed, the band edges and the modes of the
/// largest peak receptance keep theirs). The magnitude axis reaches down to
/// 1e-3 x the smallest measured |H| at most: a noise floor far below the
/// data is cut off rather than squashing the FRF.
void FillModalFitPanels(const dynamics::Frf& measured, const calibration::FrfNoise& noise,
                        const calibration::ModalFitResult& fit, const std::string& title, Axes* magnitude,
                        Axes* phase);

}  // namespace robomach::report

#include "robomach/calibration/modal_analysis.h"

namespace robomach::report {

/// A stabilisation diagram in `ax`: the poles per model order against
/// frequency (grey, the stable ones in colour) and the selected modes as
/// labelled lines (where labels cannot all be placed, those of the largest
/// `mode_strength` are kept; empty: all equal); a log frequency axis when
/// [fmin_hz, fmax_hz] spans more than two decades.
void FillStabilisationPanel(const std::vector<calibration::StabilisationPole>& poles,
                            const std::vector<double>& mode_freq_hz, double fmin_hz, double fmax_hz, Axes* ax,
                            const std::vector<double>& mode_strength = {});

/// frf-modes' picture of one posture: the stabilisation diagram of each fit
/// (poles per model order, stable ones in colour, the modes as lines), then
/// magnitude and phase of each FRF with its fit, the noise floor and the
/// usable band (FillModalFitPanels). `noise` may lack an FRF (drawn without
/// floor, every line usable).
void WriteModalAnalysisPng(const std::string& path, const calibration::PoseModes& pose,
                           const dynamics::FrfSet& measured, const calibration::NoiseModels& noise);

}  // namespace robomach::report
