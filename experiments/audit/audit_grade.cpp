// Green / amber / red for one cell of the audit (docs/audit.md "Colours"): red is a defect
// (non-finite or negative pixels, validation messages, a crash or an unexplained error, a
// blow-up); amber is a measured weakness (energy far from the bounce-matched reference, a
// firefly peak, heavy clamping, a leak, a scale dependence, out of memory, a time-out).
#include <cmath>
#include <cstdio>

#include "experiments/audit/audit.h"

namespace gilab::audit {

const char* gradeName(Grade g) {
    switch (g) {
        case Grade::NotApplicable:
            return "n/a";
        case Grade::Skipped:
            return "skipped";
        case Grade::Green:
            return "green";
        case Grade::Amber:
            return "amber";
        case Grade::Declared:
            return "declared";
        case Grade::Red:
            return "red";
    }
    return "?";
}

namespace {

std::string fmt(const char* format, double v) {
    char buf[96];
    std::snprintf(buf, sizeof buf, format, v);
    return buf;
}

/** Keeps the worst grade; its reason first. `defect` marks a red that no declaration excuses. */
struct Verdict {
    Grade grade = Grade::Green;
    std::string reasons;
    bool defect = false;
    void add(Grade g, const std::string& why, bool isDefect = false) {
        if (g == Grade::Green) return;
        defect = defect || (g == Grade::Red && isDefect);
        if (g > grade) {
            grade = g;
            reasons = why + (reasons.empty() ? "" : "; " + reasons);
        } else {
            reasons += (reasons.empty() ? "" : "; ") + why;
        }
    }
};

bool isMemoryError(const std::string& m) {
    for (const char* s : {"OUT_OF_DEVICE_MEMORY", "OUT_OF_HOST_MEMORY", "out of memory",
                          "std::bad_alloc", "DEVICE_LOST", "device lost", "exceeds the device",
                          "maxMemoryAllocationSize", "maxStorageBufferRange"})
        if (m.find(s) != std::string::npos) return true;
    return false;
}

}  // namespace

void gradeCell(CellResult& cell, const AuditCase& c, const Thresholds& t) {
    Verdict v;
    if (cell.outcome == "n/a") {
        cell.grade = Grade::NotApplicable;
        return;
    }
    if (cell.outcome == "unsupported") {
        cell.grade = Grade::Skipped;
        cell.reason = "unsupported: " + cell.message;
        return;
    }
    if (cell.outcome == "crash") v.add(Grade::Red, "crashed: " + cell.message, true);
    if (cell.outcome == "timeout") v.add(Grade::Amber, "timed out: " + cell.message);
    if (cell.outcome == "refused") {
        // A parameter case whose value is outside the declared range: a clear refusal that
        // names the parameter is the right answer; anything else is a defect.
        bool named = false;
        for (const auto& [key, value] : c.params.count(cell.technique)
                                            ? c.params.at(cell.technique)
                                            : std::map<std::string, std::string>{})
            named = named || cell.message.find(key.substr(key.rfind('.') + 1)) != std::string::npos;
        if (named) {
            cell.grade = Grade::Green;
            cell.reason = "refused: " + cell.message;
            return;
        }
        v.add(Grade::Red, "refused without naming the parameter: " + cell.message, true);
    }
    if (cell.outcome == "error")
        v.add(isMemoryError(cell.message) ? Grade::Amber : Grade::Red,
              std::string(isMemoryError(cell.message) ? "out of memory (reported): " : "failed: ") +
                  cell.message,
              true);
    const size_t bad = cell.nanPixels + cell.infPixels + cell.negativePixels;
    if (bad > 0)
        v.add(Grade::Red,
              std::to_string(cell.nanPixels) + " NaN, " + std::to_string(cell.infPixels) +
                  " Inf, " + std::to_string(cell.negativePixels) + " negative pixels",
              true);
    if (cell.validationMessages > 0)
        v.add(Grade::Red, std::to_string(cell.validationMessages) + " validation messages", true);
    if (cell.energyRatio) {
        const double e = *cell.energyRatio;
        if (std::isfinite(e) && e > t.energyRed && !c.documentedFailure.empty())
            v.add(Grade::Amber,
                  fmt("indirect energy %.3g x the matched reference: ", e) + c.documentedFailure);
        else if (!std::isfinite(e) || e > t.energyRed)
            v.add(Grade::Red, fmt("indirect energy %.3g x the matched reference (blow-up)", e));
        else if (e < t.energyGreen[0] || e > t.energyGreen[1])
            v.add(Grade::Amber, fmt("indirect energy %.3g x the matched reference", e));
    }
    if (cell.peakRatio) {
        const double p = *cell.peakRatio;
        if (!std::isfinite(p) || p > t.peakRed)
            v.add(Grade::Red, fmt("peak %.3g x the reference's (blow-up)", p));
        else if (p > t.peakAmber)
            v.add(Grade::Amber, fmt("peak %.3g x the reference's", p));
    }
    if (cell.clampedPercent && *cell.clampedPercent > t.clampAmber)
        v.add(Grade::Amber,
              fmt("clamp removed %.1f %% of the indirect light", *cell.clampedPercent));
    if (cell.leak && *cell.leak > t.leakAmber)
        v.add(Grade::Amber, fmt("leak: %.2f %% of the lit view's mean", 100.0 * *cell.leak));
    if (cell.scaleRatio) {
        // Against the path tracer's own change between the two scenes when it is known
        const double ratio = cell.scaleVsReference.value_or(*cell.scaleRatio);
        const double d = std::abs(ratio - 1.0);
        const double green = c.scaleTolerance.value_or(t.scaleGreen);
        const std::string what =
            fmt("mean %.5g x the group's base case", *cell.scaleRatio) +
            (cell.scaleVsReference
                 ? fmt(", %.5g x the path tracer's change between them", *cell.scaleVsReference)
                 : std::string());
        if (!(d <= t.scaleRed))
            v.add(Grade::Red, what);
        else if (d > green)
            v.add(Grade::Amber, what + fmt(" (green within %.2g %%)", 100.0 * green));
    }
    cell.grade = v.grade;
    cell.reason = v.reasons;
    if (v.grade == Grade::Red && !v.defect) {
        const std::map<std::string, std::string> declared = declaredWeaknesses(cell.technique);
        if (auto it = declared.find(c.name); it != declared.end()) {
            cell.grade = Grade::Declared;
            cell.declared = it->second;
            cell.reason += "; declared by the technique: " + it->second;
        }
    }
    if (cell.reason.empty() && cell.leak)
        cell.reason = fmt("leak %.3g %% of the lit view's mean", 100.0 * *cell.leak);
    else if (cell.reason.empty() && cell.energyRatio)
        cell.reason = fmt("indirect energy %.3g x matched", *cell.energyRatio);
    else if (cell.reason.empty() && cell.outcome == "ok")
        cell.reason = "finite, no validation messages";
}

void gradeReference(ReferenceResult& r, const Thresholds& t) {
    Verdict v;
    if (r.outcome == "crash") v.add(Grade::Red, "crashed: " + r.message);
    if (r.outcome == "error") v.add(Grade::Red, "failed: " + r.message);
    if (r.outcome == "timeout") v.add(Grade::Amber, "timed out: " + r.message);
    if (r.nonFiniteSamples > 0)
        v.add(Grade::Red, std::to_string(r.nonFiniteSamples) + " NaN/Inf samples");
    if (r.nonFinitePixels > 0)
        v.add(Grade::Red, std::to_string(r.nonFinitePixels) + " non-finite or negative pixels");
    if (r.pixels > 0 && double(r.fireflyPixels) > t.fireflyAmber * double(r.pixels))
        v.add(Grade::Amber, std::to_string(r.fireflyPixels) + " firefly pixels");
    if (r.scaleRatio) {
        const double d = std::abs(*r.scaleRatio - 1.0);
        const double z = r.scaleZ.value_or(0.0);
        const std::string what =
            fmt("mean %.5g x the 1 m box", *r.scaleRatio) + fmt(" (z %.2f)", z);
        if (!(d <= t.meanRed) || !(z <= t.zRed))
            v.add(Grade::Red, what);
        else if (z > t.zAmber)
            v.add(Grade::Amber, what);
    }
    r.grade = v.grade;
    r.reason = v.reasons;
    if (r.reason.empty()) r.reason = fmt("rel. error %.3f", r.relError);
}

}  // namespace gilab::audit
