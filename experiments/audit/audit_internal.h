#pragma once
/** Pieces of runAudit shared between its files (experiments/audit/). */
#include <filesystem>
#include <string>

#include "core/image/image.h"
#include "experiments/audit/audit.h"

namespace gilab::audit {

/** Where one audit writes: <out>/configs, cells, logs, references; the reference cache. */
struct AuditPaths {
    std::filesystem::path out, cache;
    std::filesystem::path configs() const { return out / "configs"; }
    std::filesystem::path cells() const { return out / "cells"; }
    std::filesystem::path logs() const { return out / "logs"; }
    std::filesystem::path references() const { return out / "references"; }
};

struct CellRequest {
    const AuditCase& c;
    const Profile& profile;
    const Catalog& catalog;
    std::string technique;
    const AuditOptions& options;
    const AuditPaths& paths;
};

/** Runs one technique x case as `gilab run` in a child process and reads what it produced. */
CellResult runCell(const CellRequest& r);

/** The reference of a scene for a case, by `gilab reference` in a child process (cached, the
 *  same key as the cells' runs), and the path tracer's checks of it. */
ReferenceResult runReferenceCheck(const AuditCase& c, const std::string& scene,
                                  const std::string& label, const Profile& profile,
                                  const AuditOptions& options, const AuditPaths& paths);

}  // namespace gilab::audit
