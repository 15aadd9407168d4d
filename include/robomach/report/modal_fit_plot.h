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
/// The edges of each usable stretch and each fitted mode are marked.
void FillModalFitPanels(const dynamics::Frf& measured, const calibration::FrfNoise& noise,
                        const calibration::ModalFitResult& fit, const std::string& title, Axes* magnitude,
                        Axes* phase);

}  // namespace robomach::report
