#pragma once

// The checks of the options_validate tests (issue #36, one vocabulary): an
// options struct's Validate() refuses a bad value with an OptionError naming
// the field, and its message holds the value and the bound.

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include <functional>
#include <string>
#include <vector>

#include "robomach/common/errors.h"

namespace robomach::testing {

/// `options` with `change` made must fail Validate() with an OptionError
/// whose field() is `field` and whose message holds each of `words` (the
/// value and the bound).
template <class Options>
void ExpectRefused(Options options, const std::function<void(Options&)>& change, const std::string& field,
                   const std::vector<std::string>& words) {
  change(options);
  try {
    options.Validate();
    ADD_FAILURE() << field << ": accepted";
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), field) << e.what();
    for (const std::string& w : words) EXPECT_THAT(e.what(), ::testing::HasSubstr(w)) << field;
  }
}

/// The OptionError `validate` throws, checked for its field and its words.
inline void ExpectOptionError(const std::function<void()>& validate, const std::string& field,
                              const std::string& words) {
  try {
    validate();
    ADD_FAILURE() << "expected OptionError for " << field;
  } catch (const OptionError& e) {
    EXPECT_EQ(e.field(), field);
    EXPECT_THAT(std::string(e.what()), ::testing::HasSubstr(words));
  }
}

}  // namespace robomach::testing
