// Issue #36, one vocabulary: PolishPlanOptions::Validate passes its
// defaults and refuses a bad value with an OptionError naming the field, its
// value and the bound. Apart from options_validate_test.cc because the
// polish-plan workflow links the CAD kernel (robomach::workflows_cad).
#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <tuple>

#include "robomach/common/errors.h"
#include "robomach/workflows/polish_plan.h"

namespace robomach::workflows {
namespace {

using ::testing::HasSubstr;

TEST(OptionsValidate, PolishPlanOptionsDefaultsPass) { EXPECT_NO_THROW(PolishPlanOptions{}.Validate()); }

TEST(OptionsValidate, PolishPlanOptionsNameFieldValueAndBound) {
  PolishPlanOptions o;
  o.sample_mm = 2.0;  // a sampling step of the path [mm]: [0.05, 0.5]
  try {
    o.Validate();
    ADD_FAILURE() << "sample_mm 2 accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), "sample_mm");
    EXPECT_THAT(e.what(), HasSubstr("sample_mm: expected a value in [0.05, 0.5]"));
    EXPECT_THAT(e.what(), HasSubstr("got 2"));
  }
}

// --face and --cad-unit-scale, checked before the file is read.
TEST(OptionsValidate, SurfaceChoiceNamesFieldAndValue) {
  EXPECT_NO_THROW(SurfaceChoice{}.Validate());
  for (const auto& [face, scale, field, text] :
       {std::tuple{-5, 1.0, "cad_face", "cad_face -5: expected a face number >= 1"},
        std::tuple{0, -5.0, "cad_unit_scale", "expected a finite factor > 0"},
        std::tuple{0, 0.0, "cad_unit_scale", "got 0"},
        std::tuple{0, HUGE_VAL, "cad_unit_scale", "got inf"}}) {
    SurfaceChoice c;
    c.cad_face = face;
    c.cad_unit_scale = scale;
    try {
      c.Validate();
      ADD_FAILURE() << field << " accepted";
    } catch (const OptionError& e) {
      EXPECT_EQ(e.field(), field);
      EXPECT_THAT(e.what(), HasSubstr(text));
    }
  }
}

}  // namespace
}  // namespace robomach::workflows
