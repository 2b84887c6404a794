// The audit's table: audit.json (every number), audit.md (docs/audit.md) and audit.html (report).
#include <cstdio>

#include "experiments/audit/audit.h"
#include "experiments/runner/run_metadata.h"

namespace gilab::audit {

using Json = nlohmann::ordered_json;

namespace {

Json optional(const std::optional<double>& v) {
    return v && std::isfinite(*v) ? Json(*v) : Json(nullptr);
}

std::string fmt(const char* format, double v) {
    char buf[64];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

/** The few characters a table cell shows: the grade and its headline number. */
std::string cellLabel(const CellResult& c) {
    if (c.grade == Grade::NotApplicable) return "-";
    if (c.grade == Grade::Skipped) return "skip";
    if (c.outcome == "refused" && c.grade == Grade::Green) return "green refused";
    std::string s = gradeName(c.grade);
    if (c.outcome == "crash") return s + " crash";
    if (c.outcome == "timeout") return s + " timeout";
    if (c.outcome == "error") return s + " error";
    if (c.nanPixels + c.infPixels + c.negativePixels > 0) return s + " nonfinite";
    if (c.validationMessages > 0) return s + " validation";
    if (c.scaleRatio) s += " x" + fmt("%.4f", *c.scaleRatio);
    if (c.scaleVsReference) s += " r" + fmt("%.4f", *c.scaleVsReference);
    if (c.energyRatio) s += " e" + fmt("%.2f", *c.energyRatio);
    if (c.leak) s += " leak " + fmt("%.2g%%", 100.0 * *c.leak);
    if (c.peakRatio && *c.peakRatio > 4.0) s += " p" + fmt("%.3g", *c.peakRatio);
    return s;
}

std::string referenceLabel(const ReferenceResult& r) {
    std::string s = gradeName(r.grade);
    if (r.outcome != "ok") return s + " " + r.outcome;
    if (r.scaleRatio)
        return s + " x" + fmt("%.5f", *r.scaleRatio) + " z" + fmt("%.1f", r.scaleZ.value_or(0));
    if (r.fireflyPixels) s += " ff" + std::to_string(r.fireflyPixels);
    return s + " " + fmt("%.3f", r.relError);
}

const CellResult* findCell(const AuditSummary& s, const std::string& c, const std::string& t) {
    for (const CellResult& cell : s.cells)
        if (cell.caseName == c && cell.technique == t) return &cell;
    return nullptr;
}

std::vector<std::string> caseOrder(const AuditSummary& s) {
    std::vector<std::string> out;
    for (const ReferenceResult& r : s.references)
        out.push_back(r.caseName);
    return out;
}

std::string htmlEscape(const std::string& text) {
    std::string out;
    for (char ch : text) {
        switch (ch) {
            case '<':
                out += "&lt;";
                break;
            case '>':
                out += "&gt;";
                break;
            case '&':
                out += "&amp;";
                break;
            case '"':
                out += "&quot;";
                break;
            default:
                out += ch;
        }
    }
    return out;
}

const char* colour(Grade g) {
    switch (g) {
        case Grade::Green:
            return "#b7e1b0";
        case Grade::Amber:
            return "#f6d08a";
        case Grade::Declared:
            return "#d9c2e6";
        case Grade::Red:
            return "#f19a9a";
        default:
            return "#e4e4e4";
    }
}

}  // namespace

Json auditJson(const AuditSummary& s, const AuditOptions& o, const Catalog& catalog) {
    Json cells = Json::array();
    for (const CellResult& c : s.cells) {
        cells.push_back({{"case", c.caseName},
                         {"technique", c.technique},
                         {"grade", gradeName(c.grade)},
                         {"declared", c.declared},
                         {"reason", c.reason},
                         {"outcome", c.outcome},
                         {"message", c.message},
                         {"exit_code", c.exitCode},
                         {"nan_pixels", c.nanPixels},
                         {"inf_pixels", c.infPixels},
                         {"negative_pixels", c.negativePixels},
                         {"validation_messages", c.validationMessages},
                         {"energy_ratio", optional(c.energyRatio)},
                         {"peak_ratio", optional(c.peakRatio)},
                         {"clamped_energy_percent", optional(c.clampedPercent)},
                         {"leak", optional(c.leak)},
                         {"scale_ratio", optional(c.scaleRatio)},
                         {"scale_vs_reference", optional(c.scaleVsReference)},
                         {"mean_luminance", c.meanLuminance},
                         {"setup_ms", c.setupMs},
                         {"frame_ms", c.frameMs},
                         {"peak_memory_mib", c.peakMemoryMiB},
                         {"run_dir", c.runDir}});
    }
    Json refs = Json::array();
    for (const ReferenceResult& r : s.references) {
        refs.push_back({{"case", r.caseName},
                        {"grade", gradeName(r.grade)},
                        {"reason", r.reason},
                        {"outcome", r.outcome},
                        {"message", r.message},
                        {"nonfinite_samples", r.nonFiniteSamples},
                        {"nonfinite_pixels", r.nonFinitePixels},
                        {"rel_error", r.relError},
                        {"firefly_pixels", r.fireflyPixels},
                        {"pixels", r.pixels},
                        {"mean_luminance", r.meanLuminance},
                        {"mean_std_error", r.meanStdError},
                        {"bounce3plus_fraction", r.tailFraction},
                        {"scale_ratio", optional(r.scaleRatio)},
                        {"scale_z", optional(r.scaleZ)},
                        {"seconds", r.seconds},
                        {"exr", r.exrPath}});
    }
    Json cases = Json::array();
    for (const AuditCase& c : catalog.cases)
        cases.push_back({{"name", c.name}, {"what", c.what}, {"scene", c.scene}});
    const Profile& p = o.quick ? catalog.quick : catalog.full;
    return {{"schema", 1},
            {"profile", o.quick ? "quick" : "full"},
            {"settings",
             {{"resolution", {p.width, p.height}},
              {"spp", p.spp},
              {"max_bounces", p.maxBounces},
              {"voxel_resolution", p.voxelResolution},
              {"validation", o.validation}}},
            {"catalog", catalog.path},
            {"provenance", cli::provenanceJson(o.commandLine)},
            {"counts",
             {{"green", s.green}, {"amber", s.amber}, {"declared", s.declared}, {"red", s.red}}},
            {"cases", cases},
            {"references", refs},
            {"cells", cells}};
}

std::string auditMarkdown(const AuditSummary& s, const std::vector<std::string>& techniques) {
    std::string md = "| case | path tracer |";
    for (const std::string& t : techniques)
        md += " " + t + " |";
    md += "\n|---|---|";
    for (size_t i = 0; i < techniques.size(); ++i)
        md += "---|";
    md += "\n";
    for (const ReferenceResult& r : s.references) {
        md += "| " + r.caseName + " | " + referenceLabel(r) + " |";
        for (const std::string& t : techniques) {
            const CellResult* c = findCell(s, r.caseName, t);
            md.append(" ").append(c ? cellLabel(*c) : std::string()).append(" |");
        }
        md += "\n";
    }
    md += "\nNot green:\n\n";
    for (const ReferenceResult& r : s.references)
        if (r.grade == Grade::Amber || r.grade == Grade::Red)
            md += "- " + r.caseName + " / path tracer: " + gradeName(r.grade) + ", " + r.reason +
                  "\n";
    for (const CellResult& c : s.cells)
        if (c.grade == Grade::Amber || c.grade == Grade::Declared || c.grade == Grade::Red)
            md += "- " + c.caseName + " / " + c.technique + ": " + gradeName(c.grade) + ", " +
                  c.reason + "\n";
    return md;
}

std::string auditHtml(const AuditSummary& s, const std::vector<std::string>& techniques,
                      const std::string& title) {
    std::string h =
        "<!doctype html><html><head><meta charset=\"utf-8\"><title>" + htmlEscape(title) +
        "</title><style>body{font-family:sans-serif}table{border-collapse:collapse}"
        "td,th{border:1px solid #999;padding:3px 6px;font-size:13px}</style></head>"
        "<body><h1>" +
        htmlEscape(title) + "</h1><p>" + std::to_string(s.green) + " green, " +
        std::to_string(s.amber) + " amber, " + std::to_string(s.declared) +
        " declared (weaknesses the technique states in its folder), " + std::to_string(s.red) +
        " red. Hover a cell for its numbers; docs/audit.md explains the colours."
        "</p><table><tr><th>case</th><th>path tracer</th>";
    for (const std::string& t : techniques)
        h += "<th>" + htmlEscape(t) + "</th>";
    h += "</tr>";
    for (const std::string& name : caseOrder(s)) {
        const ReferenceResult* r = nullptr;
        for (const ReferenceResult& ref : s.references)
            if (ref.caseName == name) r = &ref;
        h += "<tr><td>" + htmlEscape(name) + "</td><td style=\"background:" + colour(r->grade) +
             "\" title=\"" + htmlEscape(r->reason) + "\">" + htmlEscape(referenceLabel(*r)) +
             "</td>";
        for (const std::string& t : techniques) {
            const CellResult* c = findCell(s, name, t);
            if (!c) {
                h += "<td></td>";
                continue;
            }
            const std::string tip =
                c->reason + (c->outcome == "ok" ? fmt("; set-up %.0f ms", c->setupMs) +
                                                      fmt(", frame %.1f ms", c->frameMs) +
                                                      fmt(", %.0f MiB", c->peakMemoryMiB)
                                                : "");
            h += "<td style=\"background:" + std::string(colour(c->grade)) + "\" title=\"" +
                 htmlEscape(tip) + "\">" + htmlEscape(cellLabel(*c)) + "</td>";
        }
        h += "</tr>";
    }
    h += "</table></body></html>\n";
    return h;
}

}  // namespace gilab::audit
