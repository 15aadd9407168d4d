#pragma once
// The five-axis machine files (formats.md §8), one format per header:
// machine file (§8.3), encoder counts (§8.1), Siemens 840D sl compensation
// tables and temperature log (§8.4), programmed and acquired path (§8.5) and
// ISO 230-2 runs (§8.6). This header includes them all.

#include "robomach/io/acquired_path_file.h"
#include "robomach/io/compensation_file.h"
#include "robomach/io/counts_file.h"
#include "robomach/io/iso_runs_file.h"
#include "robomach/io/machine_file.h"
#include "robomach/io/program_file.h"
#include "robomach/io/temperature_log.h"
