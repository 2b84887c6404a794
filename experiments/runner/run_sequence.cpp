#include "experiments/runner/run_sequence.h"

#include <cmath>
#include <cstdio>
#include <map>

#include "core/scene/animation.h"
#include "core/util/error.h"
#include "experiments/metrics/metrics.h"
#include "experiments/runner/run_metadata.h"

namespace gilab::exp {
namespace fs = std::filesystem;

namespace {

const Image& finalLayer(const std::vector<ImageLayer>& layers) {
    const Image* image = findLayer(layers, "final");
    if (!image) throw Error("run output has no layer \"final\"");
    return *image;
}

std::string framePngName(int frame) {
    char name[32];
    std::snprintf(name, sizeof name, "frames/%03d.png", frame);
    return name;
}

double meanOf(const std::vector<double>& v) {
    double sum = 0.0;
    int n = 0;
    for (double x : v)
        if (std::isfinite(x)) sum += x, ++n;
    return n ? sum / n : std::nan("");
}

nlohmann::ordered_json numberOrNull(double v) {
    return std::isfinite(v) ? nlohmann::ordered_json(v) : nlohmann::ordered_json(nullptr);
}

}  // namespace

std::vector<int> measuredFrames(int frameCount, int frameStep) {
    std::vector<int> frames;
    for (int f = 0; f < frameCount; f += std::max(frameStep, 1))
        frames.push_back(f);
    return frames;
}

SequenceResult runSequence(FrameHarness& harness, const SequenceInputs& in) {
    const SceneAnimation& animation = in.scene.animation;
    SequenceResult out;
    fs::create_directories(in.outDir / "frames");

    metrics::MetricOptions options;
    options.tonemap = in.tonemap;
    options.ppd = in.metricsSpec.ppd;
    options.resampleFlip = false;  // error bars per frame without the costly FLIP resampling

    // Test images and references of the measured frames, in order (temporal metric).
    std::vector<Image> finals;
    std::vector<const Image*> refFull, refFullErr, refMatched, refMatchedErr;
    std::vector<MatchedReference> matched;  // kept alive for the pointers above
    matched.reserve(in.measured.size());
    nlohmann::ordered_json frames = nlohmann::ordered_json::array();
    std::vector<double> fullFlip, fullRelMse, matchedFlip;

    auto measure = [&](int frame, const std::vector<ImageLayer>& layers) {
        const Image& final = finalLayer(layers);
        matched.push_back(in.reference(frame).match(in.bounces));
        const MatchedReference& m = matched.back();
        metrics::MetricOptions o = options;
        o.referenceStdError = &m.fullStdError;
        const nlohmann::ordered_json vsFull =
            metrics::toJson(metrics::computeMetrics(final, m.full, o));
        o.referenceStdError = &m.finalStdError;
        const nlohmann::ordered_json vsMatched =
            metrics::toJson(metrics::computeMetrics(final, m.final, o));
        nlohmann::ordered_json stats = nlohmann::ordered_json::object();
        for (const auto& [name, value] : harness.stats())  // the technique's numbers this frame
            stats[name] = numberOrNull(value);
        // Every measured frame's pixels are counted like the static frame's (a NaN that appears
        // only while the light moves makes the run "nonfinite").
        size_t frameNonFinite = 0;
        const nlohmann::ordered_json finite = cli::finiteJson(layers, &frameNonFinite);
        out.nonFinitePixels += frameNonFinite;
        const Image* indirect = findLayer(layers, "indirect");
        const Image& refIndirect = m.indirect.empty() ? m.fullIndirect : m.indirect;
        const double energy =
            indirect ? metrics::computeEnergyRatio(*indirect, refIndirect) : std::nan("");
        frames.push_back({{"frame", frame},
                          {"time_s", animation.frameTime(frame)},
                          {"final_vs_full", vsFull},
                          {"final", vsMatched},
                          {"energy_ratio", numberOrNull(energy)},
                          // Mean Rec.709 luminance of the image and of the matched reference: a
                          // frame whose reference is black (a light inside a wall) shows leaks
                          {"final_mean_luminance", numberOrNull(meanLuminance(final))},
                          {"reference_mean_luminance", numberOrNull(meanLuminance(m.final))},
                          {"nonfinite", finite},
                          {"stats", stats}});
        fullFlip.push_back(vsFull["flip"].value("mean", std::nan("")));
        fullRelMse.push_back(vsFull.value("rel_mse", std::nan("")));
        matchedFlip.push_back(vsMatched["flip"].value("mean", std::nan("")));
        finals.push_back(final);
        const std::string png = framePngName(frame);
        writePngTonemapped((in.outDir / png).string(), final, in.tonemap);
        out.framePngs.push_back(png);
    };

    measure(0, in.frame0Layers);
    std::vector<FrameTiming> dynamicFrames;
    size_t next = 1;  // index into in.measured
    for (int f = 1; f < animation.frameCount; ++f) {
        harness.setFrameState(frameState(in.scene, f));
        dynamicFrames.push_back(harness.renderFrame());
        if (next < in.measured.size() && in.measured[next] == f) {
            measure(f, harness.readLayers());
            ++next;
        }
    }
    for (const MatchedReference& m : matched) {
        refFull.push_back(&m.full);
        refFullErr.push_back(&m.fullStdError);
        refMatched.push_back(&m.final);
        refMatchedErr.push_back(&m.finalStdError);
    }
    std::vector<const Image*> tests;
    for (const Image& image : finals)
        tests.push_back(&image);
    const metrics::TemporalResult temporal =
        metrics::computeTemporalInstability(tests, refFull, &refFullErr);
    const metrics::TemporalResult temporalMatched =
        metrics::computeTemporalInstability(tests, refMatched, &refMatchedErr);
    if (temporal.pairs > 0) {
        out.temporalPng = "temporal.png";
        metrics::writeTemporalMapPng((in.outDir / out.temporalPng).string(), temporal);
    }

    out.metrics = {{"frames", frames},
                   {"measured_frames", in.measured},
                   {"full_flip_mean", numberOrNull(meanOf(fullFlip))},
                   {"full_rel_mse_mean", numberOrNull(meanOf(fullRelMse))},
                   {"matched_flip_mean", numberOrNull(meanOf(matchedFlip))},
                   {"temporal", metrics::toJson(temporal)},
                   {"temporal_matched", metrics::toJson(temporalMatched)}};
    out.timing = cli::dynamicTimingJson(dynamicFrames);
    std::map<std::string, int> kinds;
    for (const FrameTiming& t : dynamicFrames)
        if (t.dynamic) ++kinds[updateKindName(t.update)];
    // A technique whose update falls back to a full rebuild on any frame is reported as such.
    out.update = kinds.count("full rebuild")  ? "full rebuild"
                 : kinds.count("incremental") ? "incremental"
                                              : "none";
    return out;
}

}  // namespace gilab::exp
