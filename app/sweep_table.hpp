// A sweep's summary table: one row per run, in run order, as CSV and as HDF5 (README.md
// "Sweeps"). Columns: run, each grid axis (the value as given), seed (with --seeds), status
// (pass / fail / error), exit (of `graspsim run`), wall_s, trace (with --keep-traces), error,
// then for each expectation "pass: WHAT" (1 met, 0 not, -1 not checked) and "measured: WHAT".
// Everything but wall_s is the same for any --jobs and on Slurm: the runs are deterministic.
#pragma once

#include <string>
#include <vector>

#include "app/sweep_plan.hpp"
#include "app/sweep_row.hpp"
#include "graspsim/recordings/sweep_table.hpp"

namespace graspsim::app::sweep {

std::string status_of(const Row& row);   // "pass" (exit 0), "fail" (exit 1), "error" (any other)

// The table's columns; a grid axis whose every value is a number is a real column.
std::vector<recordings::SweepColumn> table_columns(const Plan& plan, const std::vector<Row>& rows);
std::string csv_text(const std::vector<recordings::SweepColumn>& columns);

// Writes DIR/sweep.csv and DIR/sweep.h5 (each replaced only by a complete file); throws
// SweepError or recordings::TraceError naming the file.
void write_table(const Plan& plan, const std::string& dir, const std::vector<Row>& rows);

}  // namespace graspsim::app::sweep
