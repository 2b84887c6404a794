// The path tracer's checks of one audit case (docs/audit.md "The path tracer"): non-finite
// samples and pixels, fireflies by per-pixel variance, how much light lies past two bounces,
// and the image mean with its standard error for the scale comparison.
#include <algorithm>
#include <cmath>
#include <fstream>

#include "core/image/color.h"
#include "core/image/image_io.h"
#include "core/scene/scene_loader.h"
#include "core/util/error.h"
#include "experiments/audit/audit_internal.h"
#include "experiments/audit/child_process.h"

namespace gilab::audit {

namespace fs = std::filesystem;
using Json = nlohmann::json;

namespace {

/** Luminance of a per-channel standard error (channels treated as independent). */
double stdErrorLuminance(const Image& e, int x, int y) {
    const double r = kLuminanceR * e.at(x, y, 0), g = kLuminanceG * e.at(x, y, 1),
                 b = kLuminanceB * e.at(x, y, 2);
    return std::sqrt(r * r + g * g + b * b);
}

const Image& layer(const std::vector<ImageLayer>& layers, const std::string& name,
                   const fs::path& file) {
    const Image* image = findLayer(layers, name);
    if (!image) throw Error(file.string() + ": no layer \"" + name + "\"");
    return *image;
}

/** Adds one frame's reference (reference.json + reference.exr in `dir`) to `r`. */
void addFrame(const fs::path& dir, ReferenceResult& r, double& sumMean, double& sumVar,
              double& tail, double& indirect) {
    const Json meta = Json::parse(std::ifstream(dir / "reference.json"));
    r.nonFiniteSamples += meta.value("nonfinite_samples", size_t(0));
    const double relError = meta.value("rel_error", 0.0);
    r.seconds += meta.value("seconds", 0.0);
    const fs::path exr = dir / "reference.exr";
    r.exrPath = exr.string();
    const std::vector<ImageLayer> layers = readExrLayers(exr.string());
    const Image& full = layer(layers, "full", exr);
    const Image& err = layer(layers, "full_stderr", exr);
    const Image& emission = layer(layers, "emission", exr);
    const Image& direct = layer(layers, "direct", exr);
    const Image& b3 = layer(layers, "bounce3plus", exr);
    for (const ImageLayer& l : layers) {
        const FiniteStats s = countNonFinite(l.image);
        r.nonFinitePixels += s.nanPixels + s.infPixels + s.negativePixels;
    }
    // Fireflies: a pixel whose relative standard error is 20x the image's median and above
    // 0.5 holds a few samples far brighter than the rest (docs/audit.md).
    std::vector<double> rel;
    const double mean = meanLuminance(full);
    const double floor = std::max(1e-3 * mean, 1e-30);
    for (int y = 0; y < full.height(); ++y)
        for (int x = 0; x < full.width(); ++x) {
            const double m = luminance(full.at(x, y, 0), full.at(x, y, 1), full.at(x, y, 2));
            const double s = stdErrorLuminance(err, x, y);
            sumVar += s * s;
            if (m > floor) rel.push_back(s / m);
            const double ind =
                m - luminance(emission.at(x, y, 0), emission.at(x, y, 1), emission.at(x, y, 2)) -
                luminance(direct.at(x, y, 0), direct.at(x, y, 1), direct.at(x, y, 2));
            indirect += std::max(ind, 0.0);
            tail += luminance(b3.at(x, y, 0), b3.at(x, y, 1), b3.at(x, y, 2));
        }
    if (!rel.empty()) {
        std::vector<double> sorted = rel;
        std::nth_element(sorted.begin(), sorted.begin() + sorted.size() / 2, sorted.end());
        const double median = sorted[sorted.size() / 2];
        for (double v : rel)
            if (v > 20.0 * median && v > 0.5) ++r.fireflyPixels;
    }
    r.pixels += size_t(full.width()) * full.height();
    if (mean > 0.0) r.relError = std::max(r.relError, relError);  // a black frame has none
    sumMean += mean * full.width() * full.height();
}

}  // namespace

ReferenceResult runReferenceCheck(const AuditCase& c, const std::string& scene,
                                  const std::string& label, const Profile& profile,
                                  const AuditOptions& options, const AuditPaths& paths) {
    ReferenceResult r;
    r.caseName = c.name;
    const fs::path dir = paths.references() / label;
    const fs::path log = paths.logs() / (label + "-reference.log");
    fs::remove(log);
    bool animated = false;
    try {
        animated = loadScene(scene).animation.animated();
    } catch (const Error& e) {  // the runs will fail the same way: the cells say so too
        r.outcome = "error";
        r.message = e.what();
        return r;
    }
    std::vector<std::string> args{
        (options.executable.empty() ? selfExecutable() : options.executable),
        "reference",
        "--scene",
        scene,
        "--spp",
        std::to_string(profile.spp),
        "--max-bounces",
        std::to_string(c.maxBounces.value_or(profile.maxBounces)),
        "--pixel-filter",
        "center",
        "--seed",
        "1",
        "--resolution",
        std::to_string(c.resolution ? c.resolution->x : profile.width) + "x" +
            std::to_string(c.resolution ? c.resolution->y : profile.height),
        "--cache",
        paths.cache.string(),
        "-o",
        dir.string(),
        "-q"};
    if (c.rouletteStart >= 0)
        args.insert(args.end(), {"--roulette-depth", std::to_string(c.rouletteStart)});
    if (animated) args.insert(args.end(), {"--frames", "all"});
    const ChildExit e = runChild(args, log, profile.cellTimeoutS, options.cancel);
    if (e.cancelled || (e.exited && e.code == 130)) {
        r.outcome = "cancelled";
        return r;
    }
    if (e.timedOut || !e.exited || (e.code != 0 && e.code != 4)) {
        r.outcome = e.timedOut ? "timeout" : !e.exited ? "crash" : "error";
        r.message =
            !e.exited ? std::string("killed by signal ") + strsignal(e.signal) : lastErrorLine(log);
        return r;
    }
    double sumMean = 0.0, sumVar = 0.0, tail = 0.0, indirect = 0.0;
    std::vector<fs::path> frames;
    if (animated) {
        for (const auto& entry : fs::directory_iterator(dir))
            if (entry.path().filename().string().rfind("frame_", 0) == 0)
                frames.push_back(entry.path());
        std::sort(frames.begin(), frames.end());
    } else {
        frames.push_back(dir);
    }
    try {
        for (const fs::path& f : frames)
            addFrame(f, r, sumMean, sumVar, tail, indirect);
    } catch (const std::exception& ex) {
        r.outcome = "error";
        r.message = ex.what();
        return r;
    }
    if (r.pixels > 0) {
        r.meanLuminance = sumMean / double(r.pixels);
        r.meanStdError = std::sqrt(sumVar) / double(r.pixels);
    }
    r.tailFraction = indirect > 0.0 ? tail / indirect : 0.0;
    return r;
}

}  // namespace gilab::audit
