#include "experiments/runner/timing_probe.h"

#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/stats.h"

namespace gilab::exp {

nlohmann::ordered_json measureInstrumentationOverhead(vk::Context& vk, const Scene& scene,
                                                      int frames) {
    const char* kBaseline = "direct";
    FrameHarness harness(vk, scene, kBaseline,
                         TechniqueRegistry::instance().defaultParams(kBaseline),
                         defaultSharedParams());
    if (!harness.support().supported) return {{"skipped", harness.support().reason}};
    harness.setup();
    for (int i = 0; i < 2; ++i)
        harness.renderFrame();  // warm-up
    std::vector<double> with, without;
    for (int i = 0; i < frames; ++i) {
        harness.setTimestampsEnabled(true);
        with.push_back(harness.renderFrame().cpuMs);
        harness.setTimestampsEnabled(false);
        without.push_back(harness.renderFrame().cpuMs);
    }
    const Summary a = summarize(with), b = summarize(without);
    return {{"technique", kBaseline},
            {"scene", scene.name},
            {"frames_each", frames},
            {"frame_cpu_ms_with_timestamps", a.median},
            {"frame_cpu_ms_without_timestamps", b.median},
            {"overhead_ms", a.median - b.median},
            {"overhead_iqr_ms", std::max(a.iqr(), b.iqr())}};
}

}  // namespace gilab::exp
