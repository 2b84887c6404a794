#pragma once
/**
 * `gilab audit`: every registered technique and the path tracer over stiff and extreme cases
 * (experiments/configs/audit.json), graded green / amber / red with the number behind each
 * colour (docs/audit.md). Each technique x case is one `gilab run` in a child process, so a
 * crash, an out-of-memory error or a hang is recorded in its cell instead of ending the audit.
 */
#include <atomic>
#include <map>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <nlohmann/json.hpp>

namespace gilab::audit {

/** The settings one profile ("quick" or "full") gives every case. */
struct Profile {
    int width = 32, height = 32;
    int spp = 128;
    int maxBounces = 16;
    int voxelResolution =
        32;  // techniques with a voxel_resolution parameter, unless the case sets it
    int warmupFrames = 1;
    int frames = 1;
    double cellTimeoutS = 600.0;
};

struct AuditCase {
    std::string name;
    std::string what;               // one line: what is stiff about it
    std::string scene;              // absolute path (#variant kept); "builtin" for the built-in box
    bool quick = false;             // part of --quick
    std::optional<int> maxBounces;  // the reference's, when the case needs more than the profile
    /** Russian roulette in the reference after this bounce (closed rooms of albedo ~1, whose
     *  paths would all run to maxBounces); -1 = off. Unbiased; the same for every cell. */
    int rouletteStart = -1;
    /** Parameter cases: only the techniques listed run (others are "n/a"); values are strings
     *  as on the command line, "shared.x" keys go to the shared passes. */
    bool parameterCase = false;
    std::map<std::string, std::map<std::string, std::string>> params;
    /** Dark cases: the reference is black, so light in the image is a leak, measured against the
     *  mean of this scene's reference (a lit view of the same geometry). */
    std::string leakScale;
    /** A documented failure of the techniques this case probes (e.g. light leaking through walls
     *  thinner than a voxel): an energy excess here is amber with this text, not red. */
    std::string documentedFailure;
    /** Scale cases: the same scene at another scale or place; "" for the reference scale of
     *  the group. */
    std::string scaleGroup;
    bool scaleBase = false;
    /** Image size for this case instead of the profile's (the translated boxes: a pixel that
     *  flips at an edge must not weigh more than the tolerance). */
    std::optional<glm::ivec2> resolution;
    /** Green while |mean / the base's - 1| stays below this (the thresholds' scaleGreen when
     *  unset); the translated boxes ask for 0.2 %. */
    std::optional<double> scaleTolerance;
};

struct Catalog {
    std::string path;
    Profile quick, full;
    std::map<std::string, std::map<std::string, std::string>> techniqueParams;  // always applied
    std::vector<AuditCase> cases;
};

/** Reads the catalog strictly (unknown keys, bad values: gilab::Error naming file and key). */
Catalog loadCatalog(const std::string& path);

/** Declared: a cell that would be red for a measured weakness (an energy or peak blow-up, a
 *  scale dependence) which the technique declares in its folder's known_weaknesses.json
 *  (docs/audit.md, "Declared weaknesses"); defects (crashes, non-finite pixels, validation
 *  messages, unexplained errors) are never declared. */
enum class Grade { NotApplicable, Skipped, Green, Amber, Declared, Red };
const char* gradeName(Grade g);

/** What one technique x case produced (a subset is set, depending on how far it got). */
struct CellResult {
    std::string technique, caseName;
    std::string outcome;  // "ok", "unsupported", "refused", "error", "crash", "timeout", "n/a"
    std::string message;  // unsupported reason, error text, signal
    int exitCode = 0;
    size_t nanPixels = 0, infPixels = 0, negativePixels = 0;  // radiance layers, all frames
    uint32_t validationMessages = 0;
    std::optional<double> energyRatio;  // indirect vs the bounce-matched reference (worst frame)
    std::optional<double> claimedFraction;  // matched indirect / full indirect of the reference
    std::optional<double> peakRatio;        // max luminance of final / the reference's
    std::optional<double> clampedPercent;   // energy a near-VPL clamp removed
    std::optional<double> leak;             // dark cases: mean final / leakScale's mean
    std::optional<double> scaleRatio;       // scale cases: mean final / the group's base
    /** Scale cases: scaleRatio over the path tracer's own ratio between the two scenes, so a
     *  change of the scene itself (a box moved 20 km out is stored in 2 mm steps) is not
     *  charged to the technique; graded. */
    std::optional<double> scaleVsReference;
    double meanLuminance = 0.0;
    double setupMs = 0.0, frameMs = 0.0;
    double peakMemoryMiB = 0.0;
    std::string runDir;  // the committed run folder
    Grade grade = Grade::NotApplicable;
    std::string reason;    // the number behind the grade
    std::string declared;  // the technique's own reason, when the grade is Declared
};

/** The audit cases a technique declares it fails, case name -> why, from the text embedded as
 *  "<id>/known_weaknesses.json" (cmake/GilabTechnique.cmake); empty when it declares none.
 *  Throws gilab::Error naming the file on a malformed declaration. */
std::map<std::string, std::string> declaredWeaknesses(const std::string& technique);

/** The path tracer's checks of one case's reference. */
struct ReferenceResult {
    std::string caseName;
    std::string outcome = "ok";  // "ok", "error", "crash", "timeout"
    std::string message;
    size_t nonFiniteSamples = 0, nonFinitePixels = 0;
    double relError = 0.0;     // mean relative standard error of `full`
    size_t fireflyPixels = 0;  // per-pixel variance outliers (docs/audit.md)
    size_t pixels = 0;
    double meanLuminance = 0.0, meanStdError = 0.0;  // of `full`, over the image (all frames)
    double tailFraction = 0.0;  // bounce3plus / all indirect: how stiff the bounce series is
    std::optional<double> scaleRatio, scaleZ;  // scale cases: mean vs the base and its z-score
    double seconds = 0.0;
    std::string exrPath;
    Grade grade = Grade::Green;
    std::string reason;
};

/** Grading thresholds (docs/audit.md "Colours"). */
struct Thresholds {
    double energyGreen[2] = {0.5, 2.0};
    double energyRed = 10.0;
    double peakAmber = 4.0, peakRed = 100.0;
    double clampAmber = 25.0;  // percent
    double leakAmber = 0.01;
    double scaleGreen = 0.02, scaleRed = 0.10;  // |ratio - 1|
    double fireflyAmber = 0.001;                // fraction of pixels
    double zAmber = 3.0, zRed = 5.0, meanRed = 0.02;
};

void gradeCell(CellResult& cell, const AuditCase& c, const Thresholds& t = {});
void gradeReference(ReferenceResult& r, const Thresholds& t = {});

struct AuditOptions {
    std::string catalogPath;              // "" = experiments/configs/audit.json of the source tree
    std::vector<std::string> techniques;  // "" = every registered technique
    std::vector<std::string> cases;       // "" = every case of the profile
    bool quick = false;
    std::string outDir = "results/audit";
    std::string referenceCache;  // "" = <out>/cache
    std::string device;
    std::string executable;  // the gilab binary the cells run; "" = this process's own
    bool validation = true;
    bool quiet = false;
    std::string commandLine;
    const std::atomic<bool>* cancel = nullptr;
};

struct AuditSummary {
    std::vector<CellResult> cells;
    std::vector<ReferenceResult> references;
    size_t green = 0, amber = 0, declared = 0, red = 0;
    bool cancelled = false;
};

/** Runs the audit and writes <out>/audit.json, audit.md and audit.html. */
AuditSummary runAudit(const AuditOptions& options);

/** The table as JSON / Markdown / HTML (also used by tests). */
nlohmann::ordered_json auditJson(const AuditSummary& s, const AuditOptions& o,
                                 const Catalog& catalog);
std::string auditMarkdown(const AuditSummary& s, const std::vector<std::string>& techniques);
std::string auditHtml(const AuditSummary& s, const std::vector<std::string>& techniques,
                      const std::string& title);

}  // namespace gilab::audit
