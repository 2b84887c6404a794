// gilab: the command-line entry point. Every command lives in experiments/cli/.
#include "experiments/cli/cli.h"

int main(int argc, char** argv) {
    return gilab::cli::runMain(argc, argv);
}
