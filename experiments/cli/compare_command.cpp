#include "experiments/cli/compare_command.h"

#include "core/util/error.h"

namespace gilab::cli {

int runCompare(const CompareOptions&) { throw Error("compare: not implemented yet"); }

}  // namespace gilab::cli
