// Bad input gets a clear gilab::Error naming the file and the problem (issue 15): numbers
// beyond a double, duplicate keys and malformed JSON in scene descriptions and experiment
// configs, bad experiment names, sweeps too large to plan; and SIGTERM / SIGINT stop
// `gilab reference` and `gilab run` with exit code 130, keeping the partial reference in the
// cache (GpuSignals needs a Vulkan device, lavapipe will do).
#include <fcntl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <csignal>
#include <filesystem>
#include <fstream>
#include <functional>
#include <initializer_list>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/params/params.h"
#include "core/scene/scene_loader.h"
#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "core/util/json_reader.h"
#include "core/vk/check.h"
#include "core/vk/context.h"
#include "experiments/cli/cli.h"
#include "experiments/runner/experiment_config.h"

namespace gilab {
namespace {

namespace fs = std::filesystem;

/** A technique with two sweepable parameters, so config tests need no technique plugins. */
struct SweepProbe {
    static TechniqueInfo describe() {
        TechniqueInfo info;
        info.id = "input_errors_probe";
        info.description = "test-only technique (tests/input_errors_test.cpp)";
        info.params = {intParam("count", 1, 0, 1e6, "", "an integer to sweep"),
                       floatParam("scale", 1.0, 0.0, 1e6, "", "a number to sweep")};
        return info;
    }
};
const TechniqueRegistrar kProbe{SweepProbe::describe(),
                                [] { return std::unique_ptr<Technique>(); }};

class TempDir {
public:
    TempDir() {
        m_dir = fs::temp_directory_path() / ("gilab_input_errors_" + std::to_string(::getpid()) +
                                             "_" + std::to_string(s_counter++));
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    ~TempDir() {
        std::error_code ec;
        fs::remove_all(m_dir, ec);
    }
    const fs::path& path() const { return m_dir; }
    std::string write(const std::string& name, const std::string& text) const {
        const fs::path p = m_dir / name;
        std::ofstream(p, std::ios::binary) << text;
        return p.string();
    }

private:
    static inline int s_counter = 0;
    fs::path m_dir;
};

/** Runs `f`; expects a gilab::Error whose message holds every fragment. Returns the message. */
std::string expectError(const std::function<void()>& f,
                        std::initializer_list<std::string> fragments) {
    try {
        f();
    } catch (const Error& e) {
        const std::string message = e.what();
        for (const std::string& fragment : fragments)
            EXPECT_NE(message.find(fragment), std::string::npos)
                << "missing \"" << fragment << "\" in: " << message;
        return message;
    } catch (const std::exception& e) {
        ADD_FAILURE() << "not a gilab::Error: " << e.what();
        return e.what();
    }
    ADD_FAILURE() << "no error";
    return "";
}

const std::string kBox = R"("procedural": {"generator": "cornell_box"})";

// --- 1. Numbers beyond the range of a double ----------------------------------------------

TEST(CpuInputErrors, SceneNumberOverflowNamesFileLineAndKey) {
    TempDir dir;
    const std::string path = dir.write("overflow.json", "{\n  " + kBox + R"(,
  "lights": [
    {"type": "point", "position": [0, 1, 0], "intensity": 1e999}
  ]
})");
    const std::string m =
        expectError([&] { loadScene(path); },
                    {path + ":4:", "\"lights[0].intensity\"", "number out of range", "1e999"});
    EXPECT_EQ(m.find("json.exception"), std::string::npos) << m;
}

TEST(CpuInputErrors, SceneNegativeOverflowAndHugeIntegerInArrays) {
    TempDir dir;
    const std::string neg =
        dir.write("neg.json",
                  "{" + kBox + R"(, "camera": {"position": [0, -1e400, 3], "target": [0, 0, 0]}})");
    expectError([&] { loadSceneFile(neg); },
                {neg + ":1:", "\"camera.position[1]\"", "number out of range", "-1e400"});
    const std::string digits(400, '9');
    const std::string big =
        dir.write("big.json", "{" + kBox + ", \"exposure_ev\": " + digits + "}");
    expectError([&] { loadSceneFile(big); }, {big, "\"exposure_ev\"", "number out of range"});
}

TEST(CpuInputErrors, ExperimentNumberOverflowNamesFileAndKey) {
    TempDir dir;
    const std::string path = dir.write("overflow.json", R"({
  "name": "x",
  "scenes": ["builtin"],
  "reference": {"spp": 1e999},
  "techniques": [{"technique": "input_errors_probe"}]
})");
    expectError([&] { exp::loadExperimentConfig(path); },
                {path + ":4:", "\"reference.spp\"", "number out of range", "1e999"});
}

TEST(CpuInputErrors, MalformedAndEmptyFilesNameLineAndColumn) {
    TempDir dir;
    const std::string scene = dir.write("comma.json", "{\n  " + kBox + ",\n}\n");
    const std::string m = expectError([&] { loadSceneFile(scene); },
                                      {scene + ":3:1", "malformed JSON", "unexpected '}'"});
    EXPECT_EQ(m.find("json.exception"), std::string::npos) << m;
    const std::string empty = dir.write("empty.json", "  \n");
    expectError([&] { loadScene(empty); }, {empty, "empty file"});
    const std::string config = dir.write("trailing.json", R"({"name": "x"} extra)");
    expectError([&] { exp::loadExperimentConfig(config); },
                {config + ":1:", "malformed JSON", "expected end of input"});
    expectError([&] { exp::loadExperimentConfig(dir.path().string()); },
                {dir.path().string(), "is a folder"});
}

// --- 2. Duplicate keys ------------------------------------------------------------------------

TEST(CpuInputErrors, SceneDuplicateKeyNamesKeyPathAndLine) {
    TempDir dir;
    const std::string path = dir.write("dup.json", "{\n  " + kBox + R"(,
  "camera": {"position": [0, 1, 3],
             "position": [0, 1, 4], "target": [0, 1, 0]}
})");
    expectError([&] { loadScene(path); }, {path + ":4:14", "duplicate key \"camera.position\""});
}

TEST(CpuInputErrors, SceneDuplicateKeyAtTopLevelAndInVariants) {
    TempDir dir;
    const std::string top = dir.write("top.json", "{" + kBox + ", " + kBox + "}");
    expectError([&] { loadSceneFile(top); }, {top + ":1:", "duplicate key \"procedural\""});
    const std::string variants =
        dir.write("variants.json", "{" + kBox + R"(, "variants": {"a": {"exposure_ev": 1},
                                                                "a": {"exposure_ev": 2}}})");
    expectError([&] { loadSceneFile(variants); }, {variants, "duplicate key \"variants.a\""});
    const std::string light =
        dir.write("light.json", "{" + kBox + R"(, "lights": [{"type": "point", "intensity": 1,
                                   "intensity": 2, "position": [0, 1, 0]}]})");
    expectError([&] { loadSceneFile(light); },
                {light + ":2:", "duplicate key \"lights[0].intensity\""});
}

TEST(CpuInputErrors, ExperimentDuplicateKeyNamesKeyAndFile) {
    TempDir dir;
    const std::string path = dir.write("dup.json", R"({
  "name": "first",
  "name": "second",
  "scenes": ["builtin"],
  "reference": {"spp": 4},
  "techniques": [{"technique": "input_errors_probe"}]
})");
    expectError([&] { exp::loadExperimentConfig(path); },
                {path + ":3:3", "duplicate key \"name\""});
}

// Deep nesting (issue 31): 100,000 nested arrays once ran out of memory (each open container
// kept its full key path: memory grew with the square of the depth). Now a clear error naming
// the file, line and column, quickly, for scenes and experiments alike; 256 levels still parse.
TEST(CpuInputErrors, DeepNestingIsRefusedWithTheFileNotAnAllocationFailure) {
    TempDir dir;
    const std::string deep = std::string(100000, '[') + std::string(100000, ']');
    const std::string scene = dir.write("deep_scene.json", "{\"camera\": " + deep + "}");
    const auto t0 = std::chrono::steady_clock::now();
    expectError([&] { loadScene(scene); }, {scene + ":1:", "nested more than 256 levels"});
    const std::string config = dir.write("deep_config.json", "{\"scenes\": " + deep + "}");
    expectError([&] { exp::loadExperimentConfig(config); },
                {config + ":1:", "nested more than 256 levels"});
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count(), 2.0);
    const std::string ok = std::string(255, '[') + "1" + std::string(255, ']');
    nlohmann::json j = parseJsonText("{\"a\": " + ok.substr(1, ok.size() - 2) + "}", "ok.json");
    size_t depth = 1;  // the object
    for (const nlohmann::json* v = &j["a"]; v->is_array(); v = &(*v)[0])
        ++depth;
    EXPECT_EQ(depth, 255u);
    // Error paths still name the key inside arrays.
    expectError([&] { parseJsonText(R"({"a": [{"b": 1, "b": 2}]})", "p.json"); },
                {"p.json:1:", "duplicate key \"a[0].b\""});
}

// A description whose glTF data is missing (the shared scenes live outside the repository) says
// where it expected the data and where to read how to get it.
TEST(CpuInputErrors, MissingSceneDataNamesTheFolderAndTheScenesReadme) {
    TempDir dir;
    const std::string scene =
        dir.write("outside.json", R"({"gltf": "../no_shared/scenes/sponza/sponza.gltf"})");
    expectError([&] { loadScene(scene); }, {scene, "\"gltf\"", "sponza.gltf: glTF file not found",
                                            "not part of the repository", "no_shared/scenes/sponza",
                                            "(no such folder)", "scenes/README.md"});
}

TEST(CpuInputErrors, ParseJsonTextKeepsValidDocuments) {
    const nlohmann::json j = parseJsonText(
        R"({"a": [1, -2, 3.5, 1e-999, 18446744073709551615], "b": {"": null, "c": "\"x\""},
            "d": [[{"e": true}], []]})",
        "ok.json");
    EXPECT_EQ(j["a"].size(), 5u);
    EXPECT_EQ(j["a"][1].get<int>(), -2);
    EXPECT_EQ(j["a"][3].get<double>(), 0.0);
    EXPECT_EQ(j["b"]["c"].get<std::string>(), "\"x\"");
    EXPECT_TRUE(j["d"][0][0]["e"].get<bool>());
    EXPECT_TRUE(j["d"][1].empty());
    // The same key in two different objects is fine
    EXPECT_NO_THROW(
        parseJsonText(R"({"a": {"k": 1}, "b": {"k": 2}, "k": [{"k": 3}, {"k": 4}]})", "ok.json"));
}

// --- 3. Experiment names ----------------------------------------------------------------------

std::string configWithName(const std::string& name) {
    return nlohmann::json{{"name", name},
                          {"scenes", {"builtin"}},
                          {"reference", {{"spp", 4}}},
                          {"techniques", {{{"technique", "input_errors_probe"}}}}}
        .dump(2);
}

TEST(CpuInputErrors, ExperimentEmptyNameIsRefused) {
    TempDir dir;
    const std::string path = dir.write("noname.json", configWithName(""));
    expectError([&] { exp::loadExperimentConfig(path); },
                {path, "\"name\"", "empty name", "output root"});
}

TEST(CpuInputErrors, ExperimentNamesThatAreNotOneFolderAreRefused) {
    TempDir dir;
    for (const std::string name : {".", "..", "a/b", "../up", "a\\b", "/abs", "sp ace"}) {
        SCOPED_TRACE(name);
        const std::string path = dir.write("bad.json", configWithName(name));
        expectError([&] { exp::loadExperimentConfig(path); },
                    {path, "\"name\"", "letters, digits, '_' and '-' only"});
    }
    const std::string ok = dir.write("ok.json", configWithName("run-1_b"));
    EXPECT_EQ(exp::loadExperimentConfig(ok).name, "run-1_b");
}

// --- 4. Sweep size ----------------------------------------------------------------------------

nlohmann::json sweepConfig(int counts, int scales) {
    return {{"name", "sweep"},
            {"scenes", {"builtin"}},
            {"reference", {{"spp", 4}}},
            {"techniques",
             {{{"technique", "input_errors_probe"},
               {"sweep",
                {{"grid",
                  {{"count", {{"linear", {0, counts - 1, counts}}}},
                   {"scale", {{"linear", {0.0, 1.0, scales}}}}}}}}}}}};
}

TEST(CpuInputErrors, SweepAboveTheDefaultLimitIsRefusedBeforeExpanding) {
    TempDir dir;
    // 1000 x 1000 x 2 scenes = 2 000 000 runs: refused at once, without expanding them
    nlohmann::json j = sweepConfig(1000, 1000);
    j["scenes"] = {"builtin", {{"scene", "builtin"}, {"label", "second"}}};
    const std::string path = dir.write("big.json", j.dump(2));
    const auto start = std::chrono::steady_clock::now();
    expectError([&] { exp::loadExperimentConfig(path); },
                {path, "2000000 runs", "limit of 100000", "\"max_runs\": 2000000"});
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
}

TEST(CpuInputErrors, SweepCountsBeyondTheCeilingAndBeyond64BitsAreRefused) {
    // 1000 scenes x 10 blocks x 1000 x 1000 = 1e10 runs: above what "max_runs" may allow
    nlohmann::json j = sweepConfig(1000, 1000);
    j["scenes"] = nlohmann::json::array();
    for (int i = 0; i < 1000; ++i)
        j["scenes"].push_back({{"scene", "builtin"}, {"label", "s" + std::to_string(i)}});
    const nlohmann::json block = j["techniques"][0];
    for (int i = 0; i < 9; ++i)
        j["techniques"].push_back(block);
    expectError([&] { exp::parseExperimentConfig(j, "huge.json", "."); },
                {"huge.json", "10000000000 runs", "at most 100000000"});

    // Seven axes of 1000 values: 1e21 runs overflow 64 bits; the count saturates
    nlohmann::json k = sweepConfig(1000, 1000);
    nlohmann::json& grid = k["techniques"][0]["sweep"]["grid"];
    for (const char* key :
         {"shared.shadow_constant_bias", "shared.shadow_slope_bias", "shared.shadow_normal_offset"})
        grid[key] = {{"linear", {0.0, 8.0, 1000}}};
    grid["shared.shadow_resolution"] = {{"linear", {16, 1015, 1000}}};
    grid["shared.area_light_samples"] = {{"linear", {0, 999, 1000}}};
    expectError([&] { exp::parseExperimentConfig(k, "overflow.json", "."); },
                {"overflow.json", "more than 18446744073709551615 runs", "max_runs"});
}

// "max_runs" allows up to 1e8, but a plan that would not fit in memory is refused at once with
// what it needs (issue 31: 1,000,000 runs died after 76 s with a raw std::bad_alloc).
TEST(CpuInputErrors, PlansBeyondTheMachinesMemoryAreRefusedWithTheirSize) {
    nlohmann::json j = sweepConfig(1000, 1000);  // 1e6 a scene
    j["scenes"] = nlohmann::json::array();
    for (int i = 0; i < 64; ++i)  // 6.4e7 runs x 16 KiB = 977 GiB
        j["scenes"].push_back({{"scene", "builtin"}, {"label", "s" + std::to_string(i)}});
    j["max_runs"] = 100000000;
    const auto start = std::chrono::steady_clock::now();
    const std::string message = expectError([&] { exp::parseExperimentConfig(j, "mem.json", "."); },
                                            {"mem.json", "64000000 runs", "whose plan needs about",
                                             "GiB", "of this machine's memory", "runs fit"});
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(5));
    std::printf("%s\n", message.c_str());
    EXPECT_GT(exp::planningMemoryBudget(), size_t(0));
}

TEST(CpuInputErrors, MaxRunsRaisesAndLowersTheLimit) {
    nlohmann::json j = sweepConfig(10, 20);  // 200 runs
    EXPECT_EQ(exp::expandRuns(exp::parseExperimentConfig(j, "ok.json", ".")).size(), 200u);
    j["max_runs"] = 199;
    expectError([&] { exp::parseExperimentConfig(j, "low.json", "."); },
                {"low.json", "200 runs", "limit of 199", "\"max_runs\": 200"});
    j["max_runs"] = 200;
    EXPECT_EQ(exp::parseExperimentConfig(j, "ok.json", ".").maxRuns, 200u);
    j["max_runs"] = 0;
    expectError([&] { exp::parseExperimentConfig(j, "zero.json", "."); },
                {"zero.json", "\"max_runs\"", "out of range"});
    // A config built in memory is checked by expandRuns itself
    j["max_runs"] = 200;
    exp::ExperimentConfig c = exp::parseExperimentConfig(j, "mem.json", ".");
    c.maxRuns = 100;
    expectError([&] { exp::expandRuns(c); }, {"mem.json", "200 runs", "limit of 100"});
    EXPECT_EQ(exp::countRuns(c, 50), 50u);
}

// --set given twice for one key: refused (it silently kept the last value; issue 31).
TEST(CpuInputErrors, SetTwiceForOneKeyIsRefused) {
    ParamSet technique = TechniqueRegistry::instance().defaultParams("input_errors_probe");
    ParamSet shared = defaultSharedParams();
    expectError(
        [&] {
            cli::applyAssignments({"count=2", "count=3"}, technique, shared);
        },
        {"--set count=3", "\"count\" is already set by --set count=2"});
    expectError(
        [&] {
            cli::applyAssignments(
                {"shared.shadow_constant_bias=0.1", "shared.shadow_constant_bias=0.2"}, technique,
                shared);
        },
        {"already set by --set shared.shadow_constant_bias=0.1"});
    // Distinct keys still work, and a technique key and the shared key of one name are distinct.
    cli::applyAssignments({"count=2", "scale=0.5"}, technique, shared);
    EXPECT_EQ(technique.getInt("count"), 2);
}

// --- 5. Signals -------------------------------------------------------------------------------

/** The gilab binary next to this test's folder (build/tests/.. = build), or "" if absent. */
std::string findGilab() {
    std::error_code ec;
    const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
    if (ec) return "";
    const fs::path gilab = exe.parent_path().parent_path() / "gilab";
    return fs::is_regular_file(gilab, ec) ? gilab.string() : "";
}

std::string readText(const fs::path& path) {
    std::ifstream in(path);
    std::stringstream s;
    s << in.rdbuf();
    return s.str();
}

// `gilab render` of an animated scene says that it draws frame 0 and points to `gilab run` (it
// rendered frame 0 without a word; issue 31).
TEST(GpuRenderCommand, AnAnimatedSceneSaysItDrawsFrameZero) {
    const std::string gilab = findGilab();
    if (gilab.empty()) GTEST_SKIP() << "no gilab binary next to the tests";
    TempDir dir;
    const std::string command = gilab + " render --scene " + GILAB_SOURCE_DIR +
                                "/scenes/cornell_box.json#spot_orbit --resolution 16x16 "
                                "--warmup 0 --frames 1 -q --out " +
                                (dir.path() / "out").string() + " 2>&1";
    FILE* pipe = ::popen(command.c_str(), "r");
    ASSERT_NE(pipe, nullptr);
    std::string output;
    char buffer[4096];
    while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe))
        output.append(buffer, n);
    EXPECT_EQ(::pclose(pipe), 0) << output;
    EXPECT_NE(output.find("animated scene (9 frames): render draws its frame 0"), std::string::npos)
        << output;
    EXPECT_NE(output.find("`gilab run`"), std::string::npos) << output;
    EXPECT_NE(readText(dir.path() / "out" / "result.json").find("render draws its frame 0"),
              std::string::npos);
}

struct Interrupted {
    bool signalled = false;  // false: gilab ended (or failed) before it could be interrupted
    int exitCode = -1;       // -1: killed by a signal (or not started)
    std::string stderrText;
};

/**
 * Runs gilab with `args` (GILAB_CACHE in `dir`), sends `sig` once its stderr shows a reference
 * progress line (the handler is installed and a batch is done), and returns how it ended.
 */
Interrupted interruptGilab(const std::string& gilab, const TempDir& dir,
                           std::vector<std::string> args, int sig) {
    const fs::path errPath = dir.path() / "stderr.txt";
    const std::string cache = (dir.path() / "cache").string();
    args.insert(args.begin(), gilab);
    const pid_t pid = ::fork();
    if (pid == 0) {
        const int err = ::open(errPath.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
        const int devNull = ::open("/dev/null", O_WRONLY);
        ::dup2(err, STDERR_FILENO);
        ::dup2(devNull, STDOUT_FILENO);
        ::setenv("GILAB_CACHE", cache.c_str(), 1);
        ::signal(SIGINT, SIG_DFL);  // a test runner in the background may ignore them
        ::signal(SIGTERM, SIG_DFL);
        std::vector<char*> argv;
        for (std::string& a : args)
            argv.push_back(a.data());
        argv.push_back(nullptr);
        ::execv(gilab.c_str(), argv.data());
        ::_exit(127);
    }
    Interrupted result;
    if (pid < 0) return result;
    const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(40);
    bool rendering = false;
    while (!rendering && std::chrono::steady_clock::now() < deadline) {
        std::this_thread::sleep_for(std::chrono::milliseconds(50));
        // "[gilab] reference <scene> 1.0s 72 spp, ..." (not "[gilab] reference for <label>")
        const std::string text = readText(errPath);
        for (size_t at = text.find("[gilab] reference "); at != std::string::npos && !rendering;
             at = text.find("[gilab] reference ", at + 1))
            rendering = text.compare(at, 22, "[gilab] reference for ") != 0 &&
                        text.find(" spp", at) != std::string::npos;
        int status = 0;
        if (::waitpid(pid, &status, WNOHANG) == pid) {
            result.stderrText = readText(errPath);
            result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
            return result;
        }
    }
    if (!rendering) ADD_FAILURE() << "no reference progress line within 40 s";
    ::kill(pid, sig);
    int status = 0;
    ::waitpid(pid, &status, 0);
    result.signalled = true;
    result.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    result.stderrText = readText(errPath);
    return result;
}

/** `gilab reference` on the built-in scene with a 60 s budget, interrupted by `sig`. */
Interrupted interruptReference(const std::string& gilab, const TempDir& dir, int sig) {
    const Interrupted r = interruptGilab(
        gilab, dir,
        {"reference", "--scene", "builtin", "--time", "60", "--resolution", "16x16", "--batch", "1",
         "--max-bounces", "2", "--out", (dir.path() / "out").string()},
        sig);
    EXPECT_TRUE(r.signalled) << "gilab ended before it was interrupted: " << r.stderrText;
    return r;
}

/** One entry in $GILAB_CACHE/reference/<key>/, status "partial" (docs/reference_cache.md). */
void expectOnePartialCacheEntry(const TempDir& dir) {
    int entries = 0;
    const fs::path root = dir.path() / "cache" / "reference";
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(root, ec)) {
        if (!e.is_directory() || e.path().filename().string()[0] == '.') continue;
        ++entries;
        EXPECT_TRUE(fs::exists(e.path() / "accumulator.bin"));
        const nlohmann::json sidecar = nlohmann::json::parse(readText(e.path() / "reference.json"));
        EXPECT_EQ(sidecar.value("status", ""), "partial");
        EXPECT_GT(sidecar.value("samples", 0), 0);
    }
    EXPECT_EQ(entries, 1) << root;
}

void expectPartialReferenceKept(const TempDir& dir, const Interrupted& r) {
    EXPECT_EQ(r.exitCode, 130) << r.stderrText;
    EXPECT_NE(r.stderrText.find("partial result saved (and cached)"), std::string::npos)
        << r.stderrText;
    expectOnePartialCacheEntry(dir);
    const nlohmann::json out = nlohmann::json::parse(readText(dir.path() / "out/reference.json"));
    EXPECT_EQ(out.value("status", ""), "partial");
}

TEST(CpuSignals, ReferenceStopsOnSigtermWith130AndKeepsThePartialReference) {
    const std::string gilab = findGilab();
    if (gilab.empty()) GTEST_SKIP() << "no gilab binary next to the tests folder";
    TempDir dir;
    const Interrupted r = interruptReference(gilab, dir, SIGTERM);
    expectPartialReferenceKept(dir, r);
}

TEST(CpuSignals, ReferenceStopsOnSigintWith130AndKeepsThePartialReference) {
    const std::string gilab = findGilab();
    if (gilab.empty()) GTEST_SKIP() << "no gilab binary next to the tests folder";
    TempDir dir;
    const Interrupted r = interruptReference(gilab, dir, SIGINT);
    expectPartialReferenceKept(dir, r);
}

TEST(GpuSignals, RunStopsOnSigtermDuringAReferenceWith130AndCommitsNoRun) {
    // `gilab run` needs a Vulkan device (lavapipe will do) before it renders references
    const std::string gilab = findGilab();
    if (gilab.empty()) GTEST_SKIP() << "no gilab binary next to the tests folder";
    TempDir dir;
    const std::string config = dir.write("sigterm.json", R"({
        "name": "sigterm", "resolution": [16, 16], "scenes": ["builtin"],
        "reference": {"time_s": 60, "max_bounces": 2, "batch_spp": 1, "pixel_filter": "center"},
        "timing": {"warmup": 0, "frames": 1},
        "techniques": [{"technique": "direct"}]})");
    const fs::path results = dir.path() / "results";
    const Interrupted r =
        interruptGilab(gilab, dir, {"run", config, "--out", results.string()}, SIGTERM);
    if (!r.signalled && r.stderrText.find("[gilab] reference for") == std::string::npos)
        GTEST_SKIP() << "gilab run ended before its reference (no Vulkan device?): "
                     << r.stderrText;
    ASSERT_TRUE(r.signalled) << r.stderrText;
    EXPECT_EQ(r.exitCode, 130) << r.stderrText;
    EXPECT_EQ(r.stderrText.find("gilab: error"), std::string::npos) << r.stderrText;
    expectOnePartialCacheEntry(dir);
    // No run was committed: only temporary folders (if any) and the run locks under runs/
    std::error_code ec;
    for (const auto& e : fs::directory_iterator(results / "sigterm" / "runs", ec)) {
        const std::string name = e.path().filename().string();
        EXPECT_TRUE(name.rfind(".tmp-", 0) == 0 || name == ".locks") << e.path();
    }
    EXPECT_FALSE(fs::exists(results / "sigterm" / "results.jsonl"));
}

// --- 6. Everyday use, round 2 (issue 48) ---------------------------------------------------

struct Ran {
    int exitCode = -1;
    std::string output;  // stdout and stderr
};

/** Runs `command` through the shell in `dir`; returns its exit code and output. */
Ran runIn(const fs::path& dir, const std::string& command) {
    Ran r;
    FILE* pipe = ::popen(("cd '" + dir.string() + "' && " + command + " 2>&1").c_str(), "r");
    if (!pipe) return r;
    char buffer[4096];
    while (size_t n = std::fread(buffer, 1, sizeof buffer, pipe))
        r.output.append(buffer, n);
    const int status = ::pclose(pipe);
    r.exitCode = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    return r;
}

// Hints that tell the user to run a command name the binary the way that runs it: build/gilab
// is not on PATH (`gilab run` printed "report: gilab report ...").
TEST(CpuHints, TheCommandInHintsIsThePathThatRuns) {
    EXPECT_EQ(cli::runnableCommandPath("build/gilab", "/repo"), "build/gilab");
    EXPECT_EQ(cli::runnableCommandPath("/repo/build/gilab", "/repo"), "build/gilab");
    EXPECT_EQ(cli::runnableCommandPath("./build/../build/gilab", "/repo"), "build/gilab");
    EXPECT_EQ(cli::runnableCommandPath("./gilab", "/repo/build"), "./gilab");
    EXPECT_EQ(cli::runnableCommandPath("gilab", "/anywhere"), "gilab");  // found on PATH
    EXPECT_EQ(cli::runnableCommandPath("../build/gilab", "/repo/docs"), "/repo/build/gilab");
    EXPECT_EQ(cli::runnableCommandPath("/opt/my tools/gilab", "/home"), "'/opt/my tools/gilab'");
    EXPECT_EQ(cli::runnableCommandPath("", "/repo"), "gilab");
    EXPECT_EQ(cli::quoteForShell("results/it's"), "'results/it'\\''s'");

    // The binary, run from its folder as ./gilab, says so in its "did you mean" hint
    const std::string gilab = findGilab();
    if (gilab.empty()) GTEST_SKIP() << "no gilab binary next to the tests";
    const Ran r = runIn(fs::path(gilab).parent_path(), "./gilab lsit");
    EXPECT_EQ(r.exitCode, 2);
    EXPECT_NE(r.output.find("did you mean 'list'?\nRun './gilab --help' for the list."),
              std::string::npos)
        << r.output;
}

// `gilab run`'s last line names the command that writes the report with the binary's path as
// it was run (here bin/gilab, a link in the folder the command runs in).
TEST(GpuRunCommand, TheReportHintUsesThePathThatRuns) {
    const std::string gilab = findGilab();
    if (gilab.empty()) GTEST_SKIP() << "no gilab binary next to the tests";
    TempDir dir;
    fs::create_directories(dir.path() / "bin");
    fs::create_symlink(gilab, dir.path() / "bin" / "gilab");
    dir.write("hint.json", R"({
        "name": "hint", "resolution": [16, 16], "scenes": ["builtin"],
        "reference": {"spp": 1, "max_bounces": 0, "pixel_filter": "center"},
        "timing": {"warmup": 0, "frames": 1},
        "techniques": [{"technique": "direct"}]})");
    const Ran r = runIn(dir.path(), "GILAB_CACHE=cache bin/gilab run hint.json --out res -q");
    ASSERT_EQ(r.exitCode, 0) << r.output;
    EXPECT_NE(r.output.find("\nreport: bin/gilab report res/hint\n"), std::string::npos)
        << r.output;
}

// Every rule on a parameter's value (range, power of two, odd, extra values, the cross-parameter
// rules checkParams runs at set-up) is a usage error (exit 2) found before an output folder is
// made; `--set voxel_resolution=65` exited 1 and left an empty folder.
TEST(CpuRenderCommand, ParameterRulesAreUsageErrorsAndLeaveNoFolder) {
    const std::string gilab = findGilab();
    if (gilab.empty()) GTEST_SKIP() << "no gilab binary next to the tests";
    TempDir dir;
    const std::vector<std::pair<std::string, std::string>> cases = {
        {"-t vct --set voxel_resolution=65",
         "'voxel_resolution' must be a power of two in [32, 512], got 65"},
        {"-t vct --set voxel_resolution=1024", "must be a power of two in [32, 512], got 1024"},
        {"-t vct --set light_map_resolution=4", "must be 0 or in [8, 4096], got 4"},
        {"-t ssvp --set second_bounce_vpls=100",
         "second_bounce_vpls = 100 must be a multiple of clusters = 8"},
        {"-t direct --set shared.area_light_samples=4096 --set shared.area_shadow_resolution=4096",
         "MiB of shadow cubes"},
        {"-t vct --set storage=sparse", "must be one of {dense, octree}"}};
    for (const auto& [args, message] : cases) {
        const Ran r =
            runIn(dir.path(), gilab + " render " + args + " --resolution 16x16 -q --out out");
        EXPECT_EQ(r.exitCode, 2) << args << ": " << r.output;
        EXPECT_NE(r.output.find(message), std::string::npos) << args << ": " << r.output;
        EXPECT_FALSE(fs::exists(dir.path() / "out")) << args << " left its output folder";
    }
    // gilab reference: --sobol-replicate must be a power of two
    const Ran ref = runIn(dir.path(), gilab +
                                          " reference --sampler sobol --sobol-replicate 3 "
                                          "--spp 4 --resolution 8x8 --no-cache --out out");
    EXPECT_EQ(ref.exitCode, 2) << ref.output;
    EXPECT_NE(ref.output.find("must be a power of two"), std::string::npos) << ref.output;
    EXPECT_FALSE(fs::exists(dir.path() / "out"));
    // gilab run: a config's bad value is refused before the experiment folder is made (a bad
    // input file: exit 1, as every config error)
    dir.write("bad.json", R"({
        "name": "bad", "resolution": [16, 16], "scenes": ["builtin"],
        "reference": {"spp": 1, "max_bounces": 0, "pixel_filter": "center"},
        "techniques": [{"technique": "vct", "params": {"voxel_resolution": 65}}]})");
    const Ran run = runIn(dir.path(), gilab + " run bad.json --out res -q");
    EXPECT_EQ(run.exitCode, 1) << run.output;
    EXPECT_NE(run.output.find("bad.json"), std::string::npos) << run.output;
    EXPECT_NE(run.output.find("must be a power of two in [32, 512], got 65"), std::string::npos)
        << run.output;
    EXPECT_FALSE(fs::exists(dir.path() / "res"));
}

// An output path through a file (--out some_file/sub) is refused up front, naming the file,
// by render, run, reference and compare (a raw filesystem error came after the work).
TEST(CpuOutputFolders, APathThroughAFileIsRefusedNamingTheFile) {
    TempDir dir;
    dir.write("some_file", "x");
    expectError([&] { cli::checkOutputFolder("--out", dir.path() / "some_file" / "sub"); },
                {"cannot write to " + (dir.path() / "some_file" / "sub").string() +
                 " (--out): " + (dir.path() / "some_file").string() + " is a file, not a folder"});
    expectError([&] { cli::checkOutputFolder("--out", dir.path() / "some_file"); },
                {"some_file is a file, not a folder"});
    cli::checkOutputFolder("--out", dir.path() / "new" / "deeper");  // fine: made later
    EXPECT_FALSE(fs::exists(dir.path() / "new"));

    const std::string gilab = findGilab();
    if (gilab.empty()) GTEST_SKIP() << "no gilab binary next to the tests";
    dir.write("run.json", R"({
        "name": "cfg", "resolution": [16, 16], "scenes": ["builtin"],
        "reference": {"spp": 1, "max_bounces": 0, "pixel_filter": "center"},
        "techniques": [{"technique": "direct"}]})");
    for (const std::string& args :
         {std::string("render --resolution 8x8 --out some_file/sub"),
          std::string("reference --spp 1 --resolution 8x8 --no-cache --out some_file/sub"),
          std::string("run run.json --out some_file"),
          std::string("compare a.exr b.exr --out some_file/sub")}) {
        const Ran r = runIn(dir.path(), gilab + " " + args);
        EXPECT_EQ(r.exitCode, 2) << args << ": " << r.output;
        EXPECT_NE(r.output.find("some_file is a file, not a folder"), std::string::npos)
            << args << ": " << r.output;
    }
}

// Out of memory at set-up names the resolution, the resource and its size, and advises a smaller
// --resolution (it printed the raw vkBindImageMemory failure).
TEST(CpuRenderCommand, OutOfMemoryNamesTheResolutionAndTheResource) {
    const vk::OutOfMemoryError e("binding", "image", "shared/gbuffer.position", uint64_t(4) << 30,
                                 VK_ERROR_OUT_OF_DEVICE_MEMORY);
    EXPECT_EQ(std::string(e.what()),
              "binding 4294967296 bytes (4096 MiB) of memory to image 'shared/gbuffer.position' "
              "failed: VK_ERROR_OUT_OF_DEVICE_MEMORY");
    const std::string m = cli::describeOutOfMemory(16384, 16384, e);
    EXPECT_EQ(m.rfind("out of memory at 16384x16384: binding 4294967296 bytes (4096 MiB)", 0), 0u)
        << m;
    EXPECT_NE(m.find("try a smaller --resolution (e.g. 8192x8192)"), std::string::npos) << m;
    // A DeviceLimitError, so an experiment records the run as unsupported and goes on
    EXPECT_NE(dynamic_cast<const DeviceLimitError*>(&e), nullptr);
}

// The render itself: lavapipe cannot bind a 16384^2 RGBA32F G-buffer image (4 GiB); a device
// that can is skipped (it would render 16384^2).
TEST(GpuRenderCommand, AResolutionTooLargeForTheDeviceSaysSoAndLeavesNoFolder) {
    const std::string gilab = findGilab();
    if (gilab.empty()) GTEST_SKIP() << "no gilab binary next to the tests";
    {
        vk::Context ctx;
        if (ctx.deviceName().find("llvmpipe") == std::string::npos)
            GTEST_SKIP() << ctx.deviceName() << " may hold 16384^2 images: not rendered";
    }
    TempDir dir;
    const Ran r =
        runIn(dir.path(), gilab + " render --resolution 16384x16384 -t direct -q --out x");
    EXPECT_EQ(r.exitCode, 1) << r.output;
    EXPECT_NE(r.output.find("gilab: error: out of memory at 16384x16384: "), std::string::npos)
        << r.output;
    EXPECT_NE(r.output.find("try a smaller --resolution (e.g. 8192x8192)"), std::string::npos)
        << r.output;
    EXPECT_FALSE(fs::exists(dir.path() / "x"));
}

}  // namespace
}  // namespace gilab
