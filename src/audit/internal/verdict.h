#pragma once

// The graded verdict of an audit (issue #18, #33). Private to src/audit.
#include "robomach/audit/model_audit.h"

namespace robomach::audit::internal {

/// Grade, graded candidate, its numbers, verdict, pattern, reasons and
/// headline of `r` from its candidates.
void GradeVerdict(const AuditOptions& o, AuditResult* r);

/// AuditResult::headline.
std::string Headline(const AuditResult& r, const AuditOptions& o);

}  // namespace robomach::audit::internal
