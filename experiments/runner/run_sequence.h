#pragma once
/**
 * An animated scene's run after its static part (docs/experiments.md "Animated scenes"): the
 * harness walks frames 1..N-1 of the animation in order (every one a dynamic frame: the light or
 * camera moved, the technique's update runs inside the frame), and on the measured frames
 * (every frameStep-th, from 0) the image is compared with that frame's reference. Frame 0 is the
 * run's static image. Also the temporal instability over the measured frames
 * (docs/metrics.md "Temporal instability").
 */
#include <filesystem>
#include <functional>
#include <vector>

#include <nlohmann/json.hpp>

#include "core/image/image.h"
#include "core/image/image_io.h"
#include "core/technique/frame_harness.h"
#include "experiments/runner/experiment_config.h"
#include "experiments/runner/reference_set.h"

namespace gilab::exp {

/** Frames 0, k, 2k, ... < frameCount. */
std::vector<int> measuredFrames(int frameCount, int frameStep);

struct SequenceResult {
    nlohmann::ordered_json metrics;      // metrics.sequence: frames[], means, temporal blocks
    nlohmann::ordered_json timing;       // dynamic_frame_*_ms, update_cpu_ms, update_passes
    std::vector<std::string> framePngs;  // relative to the run folder
    std::string temporalPng;
    std::string update;          // the update kind of the dynamic frames ("incremental", ...)
    size_t nonFinitePixels = 0;  // NaN/Inf/negative pixels over the measured frames' layers
};

struct SequenceInputs {
    const Scene& scene;  // the static scene (frame 0 state), with its animation
    int bounces = 0;     // the technique's claimed bounces (matched references)
    std::vector<int> measured;
    const std::vector<ImageLayer>& frame0Layers;  // the static part's read-back (frame 0)
    /** The reference of frame f (cached by the caller). */
    std::function<const ReferenceSet&(int frame)> reference;
    const MetricOptionsSpec& metricsSpec;
    ToneMap tonemap;
    std::filesystem::path outDir;  // the run's temporary folder: frames/NNN.png, temporal.png
};

SequenceResult runSequence(FrameHarness& harness, const SequenceInputs& in);

}  // namespace gilab::exp
