// Validation messages never pass silently: a run with any Vulkan validation message gets status
// "invalid" (stored, counted, redone next time) and a non-zero exit code, in `gilab render` and
// in `gilab run`. The message is provoked for real by a technique that records a bad barrier.
#include <unistd.h>

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/technique/registry.h"
#include "experiments/cli/cli.h"
#include "experiments/cli/interrupt.h"
#include "experiments/runner/run_metadata.h"
#include "experiments/runner/run_store.h"
#include "experiments/runner/runner.h"
#include "tests/gpu_test_fixture.h"

namespace gilab::test {
namespace {

namespace fs = std::filesystem;

/**
 * A barrier the validation layer rejects (colour-attachment writes are not an access of the
 * compute-shader stage) but every device executes harmlessly, unlike e.g. a dispatch over
 * maxComputeWorkGroupCount, which would run billions of groups where that limit is 2^31 - 1.
 */
void recordInvalidBarrier(VkCommandBuffer cmd) {
    VkMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
    barrier.srcStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    barrier.srcAccessMask = VK_ACCESS_2_COLOR_ATTACHMENT_WRITE_BIT;
    barrier.dstStageMask = VK_PIPELINE_STAGE_2_COMPUTE_SHADER_BIT;
    barrier.dstAccessMask = VK_ACCESS_2_SHADER_READ_BIT;
    VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
    dependency.memoryBarrierCount = 1;
    dependency.pMemoryBarriers = &barrier;
    vkCmdPipelineBarrier2(cmd, &dependency);
}

/** Renders nothing (indirect stays zero) and records the invalid barrier in every frame. */
class InvalidBarrierTechnique final : public Technique {
public:
    static TechniqueInfo describe() {
        TechniqueInfo info;
        info.id = "test_invalid_barrier";
        info.description = "test only: records a barrier the validation layer rejects";
        return info;
    }
    void setup(TechniqueContext&) override {}
    void render(TechniqueContext&, VkCommandBuffer cmd, FrameTargets&) override {
        recordInvalidBarrier(cmd);
    }
};

GILAB_REGISTER_TECHNIQUE(InvalidBarrierTechnique)

fs::path tempDir(const std::string& name) {
    const fs::path dir =
        fs::temp_directory_path() / ("gilab_validation_" + name + "_" + std::to_string(::getpid()));
    fs::remove_all(dir);
    fs::create_directories(dir);
    return dir;
}

nlohmann::json readJson(const fs::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
}

TEST(CpuRunStatus, AnyValidationMessageMakesTheRunInvalid) {
    using exp::runStatus;
    EXPECT_EQ(runStatus({}), "ok");
    EXPECT_EQ(runStatus({.nonFinitePixels = 3}), "nonfinite");
    EXPECT_EQ(runStatus({.supported = false}), "unsupported");
    EXPECT_EQ(runStatus({.validationMessages = 1}), "invalid");
    EXPECT_EQ(runStatus({.nonFinitePixels = 3, .validationMessages = 2}), "invalid");
    EXPECT_EQ(runStatus({.supported = false, .validationMessages = 1}), "invalid");
}

TEST(CpuRunStatus, ValidationCountAddsErrorsAndWarnings) {
    EXPECT_EQ(cli::validationMessageCount({{"errors", 2}, {"warnings", 1}}), 3u);
    EXPECT_EQ(cli::validationMessageCount({{"errors", 0}, {"warnings", 0}}), 0u);
    EXPECT_EQ(cli::validationMessageCount(nullptr), 0u);
    EXPECT_EQ(cli::validationMessageCount({{"errors", "many"}}), 0u);
}

TEST(CpuRunStatus, ExitCodesFollowTheStatus) {
    EXPECT_EQ(cli::exitCodeForStatus("ok"), cli::kExitOk);
    EXPECT_EQ(cli::exitCodeForStatus("nonfinite"), cli::kExitNonFinite);
    EXPECT_EQ(cli::exitCodeForStatus("unsupported"), cli::kExitUnsupported);
    EXPECT_EQ(cli::exitCodeForStatus("invalid"), cli::kExitInvalid);
    EXPECT_EQ(cli::kExitInvalid, 5);

    exp::RunnerSummary s;
    EXPECT_EQ(cli::runExitCode(s, false), cli::kExitOk);
    s.nonfinite = 1;
    EXPECT_EQ(cli::runExitCode(s, false), cli::kExitNonFinite);
    s.invalid = 1;
    EXPECT_EQ(cli::runExitCode(s, false), cli::kExitInvalid);
    EXPECT_EQ(cli::runExitCode(s, true), cli::kExitInterrupted);
    exp::RunnerSummary probe;
    probe.validationOutsideRuns = 1;
    EXPECT_EQ(cli::runExitCode(probe, false), cli::kExitInvalid);
}

TEST(CpuRunStatus, InvalidRunsAreStoredButNotFinished) {
    const fs::path dir = tempDir("store");
    exp::RunStore store(dir);
    const nlohmann::ordered_json result = {
        {"key", "k1"},
        {"index", 0},
        {"status", "invalid"},
        {"validation", {{"errors", 1}, {"warnings", 2}, {"messages", {"[error] x"}}}}};
    fs::create_directories(store.runDir("k1"));
    std::ofstream(store.runDir("k1") / "result.json") << result.dump(2);
    EXPECT_EQ(store.storedStatus("k1"), "invalid");
    EXPECT_FALSE(store.isFinished("k1"));  // redone by the next `gilab run`
    EXPECT_EQ(store.loadFinished().size(), 1u);
    const nlohmann::ordered_json row = exp::resultRow(result);
    EXPECT_EQ(row["status"], "invalid");
    EXPECT_EQ(row["validation_errors"], 1);
    EXPECT_EQ(row["validation_warnings"], 2);
    fs::remove_all(dir);
}

class GpuValidationStatus : public ValidatedGpuTest {};

TEST_F(GpuValidationStatus, RealMessageIsCapturedTakenAndMakesTheRunInvalid) {
    m_ctx->submitAndWait(recordInvalidBarrier);
    const nlohmann::ordered_json validation = cli::takeValidationJson(*m_ctx);
    EXPECT_EQ(validation["enabled"], true);
    EXPECT_GE(validation["errors"].get<uint32_t>(), 1u);
    ASSERT_FALSE(validation["messages"].empty());
    EXPECT_EQ(validation["messages"][0].get<std::string>().rfind("[error] ", 0), 0u);
    const uint32_t count = cli::validationMessageCount(validation);
    EXPECT_EQ(exp::runStatus({.validationMessages = count}), "invalid");
    // Taken: the next run starts clean (and the fixture's own check passes).
    EXPECT_EQ(m_ctx->validationErrorCount() + m_ctx->validationWarningCount(), 0u);
    EXPECT_TRUE(m_ctx->validationMessages().empty());
}

TEST(GpuInvalidRuns, RenderSavesInvalidStatusAndExitsWithCode5) {
    const fs::path out = tempDir("render");
    cli::RenderOptions o;
    o.technique = "test_invalid_barrier";
    o.outDir = out.string();
    o.resolution = "16x16";
    o.warmupFrames = 0;
    o.frames = 1;
    o.quiet = true;
    o.validation = true;
    EXPECT_EQ(cli::runRender(o), cli::kExitInvalid);

    const nlohmann::json meta = readJson(out / "result.json");
    EXPECT_EQ(meta["status"], "invalid");
    EXPECT_GE(meta["validation"]["errors"].get<uint32_t>(), 1u);
    EXPECT_FALSE(meta["validation"]["messages"].empty());
    EXPECT_TRUE(fs::exists(out / "output.exr"));  // outputs kept for inspection
    fs::remove_all(out);
}

TEST(GpuInvalidRuns, RunnerStoresInvalidRunCountsItAndRedoesIt) {
    const fs::path dir = tempDir("runner");
    const fs::path config = dir / "invalid.json";
    std::ofstream(config) << R"({
        "name": "invalid", "resolution": [16, 16], "scenes": ["builtin"],
        "reference": {"spp": 8, "max_bounces": 2, "pixel_filter": "center"},
        "timing": {"warmup": 0, "frames": 1},
        "techniques": [{"technique": "test_invalid_barrier"}, {"technique": "direct"}]
    })";
    exp::RunnerOptions o;
    o.configPath = config.string();
    o.outRoot = (dir / "results").string();
    o.referenceCacheDir = (dir / "cache").string();
    o.quiet = true;
    o.validation = true;

    exp::RunnerSummary s = exp::runExperiment(o);
    EXPECT_EQ(s.ran, 2u);  // the invalid run does not stop the others
    EXPECT_EQ(s.invalid, 1u);
    EXPECT_EQ(s.validationOutsideRuns, 0u);
    EXPECT_EQ(cli::runExitCode(s, false), cli::kExitInvalid);

    const exp::RunStore store(s.dir);
    const auto runs = store.loadFinished();
    ASSERT_EQ(runs.size(), 2u);
    for (const auto& r : runs) {
        const bool bad = r["technique"]["id"] == "test_invalid_barrier";
        EXPECT_EQ(r["status"], bad ? "invalid" : "ok");
        EXPECT_EQ(cli::validationMessageCount(r["validation"]) > 0, bad);  // each run its own
        EXPECT_EQ(store.isFinished(r["key"]), !bad);
        EXPECT_TRUE(fs::exists(store.runDir(r["key"]) / "final.png"));
    }
    std::ifstream rows(s.dir / "results.jsonl");
    std::string line;
    size_t invalidRows = 0;
    while (std::getline(rows, line))
        invalidRows += nlohmann::json::parse(line)["status"] == "invalid";
    EXPECT_EQ(invalidRows, 1u);

    s = exp::runExperiment(o);  // the invalid run is redone, the ok one kept
    EXPECT_EQ(s.ran, 1u);
    EXPECT_EQ(s.alreadyFinished, 1u);
    EXPECT_EQ(s.invalid, 1u);
    fs::remove_all(dir);
}

}  // namespace
}  // namespace gilab::test
