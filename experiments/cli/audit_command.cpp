// `gilab audit`: the stability table (experiments/audit/audit.h, docs/audit.md).
#include <cstdio>

#include "experiments/audit/audit.h"
#include "experiments/cli/cli.h"
#include "experiments/cli/interrupt.h"

namespace gilab::cli {

int runAuditCommand(audit::AuditOptions options) {
    for (const std::string& t : options.techniques)
        checkTechniqueName(t);
    InterruptScope interrupt(
        "\ngilab: interrupted: stopping after the current cell; the table so far is kept "
        "(a second Ctrl-C or SIGTERM aborts)\n");
    if (!options.cancel) options.cancel = &interrupt.flag();
    const audit::AuditSummary s = audit::runAudit(options);
    std::printf(
        "audit: %zu green, %zu amber, %zu declared, %zu red%s\n  table: %s/audit.md, "
        "%s/audit.html, every number: %s/audit.json\n",
        s.green, s.amber, s.declared, s.red, s.cancelled ? " (interrupted: partial table)" : "",
        options.outDir.c_str(), options.outDir.c_str(), options.outDir.c_str());
    if (s.cancelled || interrupt.interrupted()) return kExitInterrupted;
    return s.red > 0 ? kExitAuditRed : kExitOk;
}

}  // namespace gilab::cli
