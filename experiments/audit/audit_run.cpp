// runAudit: the reference checks and the technique x case cells in order, then the scale
// comparisons; the table is rewritten after every cell so a killed audit keeps what it has.
#include <algorithm>
#include <cmath>
#include <cstdio>

#include "core/technique/registry.h"
#include "core/util/atomic_file.h"
#include "core/util/build_info.h"
#include "core/util/error.h"
#include "experiments/audit/audit_internal.h"

namespace gilab::audit {

namespace fs = std::filesystem;

namespace {

std::vector<const AuditCase*> selectCases(const Catalog& catalog, const AuditOptions& o) {
    std::vector<const AuditCase*> out;
    for (const std::string& name : o.cases) {
        bool known = false;
        for (const AuditCase& c : catalog.cases)
            known = known || c.name == name;
        if (!known) {
            std::string list;
            for (const AuditCase& c : catalog.cases)
                list += (list.empty() ? "" : ", ") + c.name;
            throw Error("audit: unknown case \"" + name + "\" in " + catalog.path +
                        " (cases: " + list + ")");
        }
    }
    for (const AuditCase& c : catalog.cases) {
        const bool named = std::find(o.cases.begin(), o.cases.end(), c.name) != o.cases.end();
        if (o.cases.empty() ? (!o.quick || c.quick) : named) out.push_back(&c);
    }
    return out;
}

void writeOutputs(const AuditSummary& s, const AuditOptions& o, const Catalog& catalog,
                  const std::vector<std::string>& techniques, const fs::path& out, bool complete) {
    nlohmann::ordered_json j = auditJson(s, o, catalog);
    j["complete"] = complete;
    writeFileAtomic(out / "audit.json", j.dump(2) + "\n");
    writeFileAtomic(out / "audit.md", auditMarkdown(s, techniques));
    writeFileAtomic(
        out / "audit.html",
        auditHtml(s, techniques, std::string("gilab audit") + (o.quick ? " --quick" : "")));
}

void printCell(const CellResult& c, bool quiet) {
    if (quiet) return;
    std::printf("  %-8s %-7s %s", c.technique.c_str(), gradeName(c.grade), c.reason.c_str());
    if (c.outcome == "ok")
        std::printf(" [set-up %.2f s, frame %.1f ms, %.0f MiB]", c.setupMs * 1e-3, c.frameMs,
                    c.peakMemoryMiB);
    std::printf("\n");
    std::fflush(stdout);
}

/** Scale groups: each case's mean against its group's base case, per technique and for the
 *  path tracer (the same seed, so the z-score is conservative). */
void compareScales(AuditSummary& s, const std::vector<const AuditCase*>& cases) {
    for (const AuditCase* base : cases) {
        if (!base->scaleBase) continue;
        const ReferenceResult* baseRef = nullptr;
        for (const ReferenceResult& r : s.references)
            if (r.caseName == base->name) baseRef = &r;
        for (const AuditCase* other : cases) {
            if (other->scaleGroup != base->scaleGroup || other == base) continue;
            for (ReferenceResult& r : s.references) {
                if (r.caseName != other->name || !baseRef || baseRef->meanLuminance <= 0.0 ||
                    r.outcome != "ok")
                    continue;
                r.scaleRatio = r.meanLuminance / baseRef->meanLuminance;
                const double se = std::hypot(r.meanStdError, baseRef->meanStdError);
                r.scaleZ = se > 0.0 ? std::abs(r.meanLuminance - baseRef->meanLuminance) / se : 0.0;
                gradeReference(r);
            }
            const ReferenceResult* otherRef = nullptr;
            for (const ReferenceResult& r : s.references)
                if (r.caseName == other->name && r.scaleRatio) otherRef = &r;
            for (CellResult& c : s.cells) {
                if (c.caseName != other->name || c.outcome != "ok") continue;
                for (const CellResult& b : s.cells)
                    if (b.caseName == base->name && b.technique == c.technique &&
                        b.outcome == "ok" && b.meanLuminance > 0.0)
                        c.scaleRatio = c.meanLuminance / b.meanLuminance;
                if (c.scaleRatio && otherRef && *otherRef->scaleRatio > 0.0)
                    c.scaleVsReference = *c.scaleRatio / *otherRef->scaleRatio;
                gradeCell(c, *other);
            }
        }
    }
}

}  // namespace

AuditSummary runAudit(const AuditOptions& o) {
    const std::string catalogPath =
        o.catalogPath.empty() ? std::string(build::kSourceDir) + "/experiments/configs/audit.json"
                              : o.catalogPath;
    const Catalog catalog = loadCatalog(catalogPath);
    const Profile& profile = o.quick ? catalog.quick : catalog.full;
    const std::vector<const AuditCase*> cases = selectCases(catalog, o);
    std::vector<std::string> techniques = o.techniques;
    if (techniques.empty())
        for (const TechniqueInfo* info : TechniqueRegistry::instance().list())
            techniques.push_back(info->id);
    // Each technique's declared weaknesses are read before any cell runs, so a malformed file or
    // a case name the catalog does not have (a typo would never apply) stops the audit up front.
    for (const std::string& t : techniques)
        for (const auto& [name, why] : declaredWeaknesses(t)) {
            const bool known = std::any_of(catalog.cases.begin(), catalog.cases.end(),
                                           [&](const AuditCase& c) { return c.name == name; });
            if (!known)
                throw Error(t + "/known_weaknesses.json declares case \"" + name +
                            "\", which the catalog " + catalogPath + " does not have");
        }
    AuditPaths paths;
    paths.out = o.outDir;
    paths.cache = o.referenceCache.empty() ? paths.out / "cache" : fs::path(o.referenceCache);
    fs::create_directories(paths.out);

    AuditSummary s;
    size_t index = 0;
    for (const AuditCase* c : cases) {
        ++index;
        if (!o.quiet) {
            std::printf("[%zu/%zu] %s: %s\n", index, cases.size(), c->name.c_str(),
                        c->what.c_str());
            std::fflush(stdout);
        }
        ReferenceResult ref = runReferenceCheck(*c, c->scene, c->name, profile, o, paths);
        if (ref.outcome == "cancelled") {
            s.cancelled = true;
            break;
        }
        gradeReference(ref);
        if (!o.quiet)
            std::printf("  %-8s %-7s %s [%.1f s]\n", "path tracer", gradeName(ref.grade),
                        ref.reason.c_str(), ref.seconds);
        s.references.push_back(ref);
        std::optional<double> leakMean;
        if (!c->leakScale.empty()) {
            const ReferenceResult lit =
                runReferenceCheck(*c, c->leakScale, c->name + "_lit", profile, o, paths);
            if (lit.outcome == "cancelled") {
                s.cancelled = true;
                break;
            }
            if (lit.outcome == "ok" && lit.meanLuminance > 0.0) leakMean = lit.meanLuminance;
        }
        for (const std::string& t : techniques) {
            CellResult cell;
            if (c->parameterCase && !c->params.count(t)) {
                cell.technique = t;
                cell.caseName = c->name;
                cell.outcome = "n/a";
            } else {
                cell = runCell({*c, profile, catalog, t, o, paths});
            }
            if (cell.outcome == "cancelled") {
                s.cancelled = true;
                break;
            }
            if (leakMean && cell.outcome == "ok") cell.leak = cell.meanLuminance / *leakMean;
            gradeCell(cell, *c);
            if (cell.outcome != "n/a") printCell(cell, o.quiet);
            s.cells.push_back(cell);
            writeOutputs(s, o, catalog, techniques, paths.out, false);
        }
        if (s.cancelled) break;
    }
    compareScales(s, cases);
    for (const CellResult& c : s.cells) {
        s.green += c.grade == Grade::Green;
        s.amber += c.grade == Grade::Amber;
        s.declared += c.grade == Grade::Declared;
        s.red += c.grade == Grade::Red;
    }
    for (const ReferenceResult& r : s.references) {
        s.green += r.grade == Grade::Green;
        s.amber += r.grade == Grade::Amber;
        s.red += r.grade == Grade::Red;
    }
    writeOutputs(s, o, catalog, techniques, paths.out, !s.cancelled);
    return s;
}

}  // namespace gilab::audit
