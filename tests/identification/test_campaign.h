#pragma once

// Shared by the identification tests: the KR210 model of config/kr210.yaml
// and seed-shaped synthetic campaigns.

#include <memory>
#include <string>
#include <vector>

#include "robomach/dynamics/robot_model.h"
#include "robomach/identification/campaign_synth.h"
#include "robomach/io/robot_config.h"
#include "test_support.h"

namespace robomach::testing {

inline std::shared_ptr<const dynamics::RobotModel> Kr210() {
  static const auto model = io::LoadRobotConfig(SourcePath("config/kr210.yaml")).Build();
  return model;
}

/// The seed's campaign shape: `num_postures` postures, two rope directions
/// (pulleys), 10/20/30 kg, tracker noise 0.01 mm, the default bracket load
/// point and target of CampaignOptions.
inline std::vector<identification::TrackerMeasurement> SeedCampaign(
    unsigned seed, int num_postures = 12, identification::CampaignOptions o = {},
    std::vector<int>* outliers = nullptr) {
  const auto model = Kr210();
  o.seed = seed;
  const auto postures = identification::CampaignPostures(*model, num_postures, o, 1000 + seed);
  std::vector<std::string> ids;
  for (int p = 0; p < num_postures; ++p) ids.push_back("P" + std::to_string(p + 1));
  return identification::SimulateCampaign(*model, ids, postures, model->joint_stiffness(), o, outliers);
}

}  // namespace robomach::testing
