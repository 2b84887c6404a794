#pragma once
/** `gilab run --dry-run`'s listing (docs/experiments.md, "--dry-run"). */
#include <string>
#include <vector>

#include "experiments/runner/experiment_config.h"
#include "experiments/runner/run_store.h"

namespace gilab::exp {

/**
 * Prints `runs` (their keys beside them) as a tab-separated table: index, key, state, scene,
 * technique, then the parameter columns of results.csv whose value changes between runs of one
 * technique (param.* first, in spec order). The others are printed once, above the table, as
 * "# ... constant for all runs: k=v ..." and "# constant for <technique> runs: k=v ..." lines.
 */
void printDryRun(const std::vector<const RunSpec*>& runs, const std::vector<std::string>& keys,
                 const RunStore& store);

}  // namespace gilab::exp
