// A seeded mutation fuzzer over the input loaders (issue 15): the shipped scene descriptions,
// the Cornell box glTF (with its .bin) and the experiment configs, mutated byte- and
// token-wise, must load or fail with a gilab::Error, never another exception (a crash fails the
// whole test binary). Mutated files are written to a temporary folder only. Deterministic: a fixed
// seed per input. A failing input is written to the temporary folder named in the failure; add it
// to tests/fuzz_corpus/ as a regression.
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/scene/scene_loader.h"
#include "core/util/error.h"
#include "experiments/audit/audit.h"
#include "experiments/runner/experiment_config.h"

namespace fs = std::filesystem;

namespace gilab {
namespace {

const fs::path kRoot = GILAB_SOURCE_DIR;

std::string readAll(const fs::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
}

void writeAll(const fs::path& p, const std::string& text) {
    std::ofstream(p, std::ios::binary) << text;
}

/** One to four random edits: byte flips, inserts, deletions, duplicated spans, numbers
 *  replaced by extreme ones, truncation. */
std::string mutate(std::string s, std::mt19937& rng) {
    static const char* kTokens[] = {
        "1e999", "-1e999", "-1", "0",    "4294967296", "-0",   "1e-999", "null",
        "true",  "[]",     "{}", "\"\"", "2147483648", "1e38", "NaN",    "-2147483649"};
    auto pick = [&](size_t n) { return n == 0 ? size_t(0) : size_t(rng() % n); };
    const int edits = 1 + int(rng() % 4);
    for (int e = 0; e < edits && !s.empty(); ++e) {
        const size_t at = pick(s.size());
        switch (rng() % 6) {
            case 0:
                s[at] = char(rng() % 256);
                break;
            case 1:
                s.insert(at, 1, "{}[],:\"0-e."[rng() % 11]);
                break;
            case 2:
                s.erase(at, 1 + pick(16));
                break;
            case 3: {
                const size_t len = 1 + pick(64);
                s.insert(pick(s.size()), s.substr(at, len));
                break;
            }
            case 4: {  // replace the number starting at or after `at`
                size_t b = s.find_first_of("-0123456789", at);
                if (b == std::string::npos) break;
                size_t end = s.find_first_not_of("-+0123456789.eE", b);
                s.replace(b, (end == std::string::npos ? s.size() : end) - b,
                          kTokens[rng() % (sizeof(kTokens) / sizeof(kTokens[0]))]);
                break;
            }
            default:
                s.resize(at);
                break;
        }
    }
    return s;
}

enum class Loader { Scene, Gltf, Config, AuditCatalog };

/** Loads `path`; "" when it loaded or failed with gilab::Error, else what else it threw.
 *  `loaded` (optional) counts the inputs that loaded. */
std::string tryLoad(Loader kind, const fs::path& path, int* loaded = nullptr) {
    try {
        if (kind == Loader::Config)
            (void)exp::loadExperimentConfig(path.string());
        else if (kind == Loader::AuditCatalog)
            (void)audit::loadCatalog(path.string());
        else if (kind == Loader::Gltf)
            (void)loadGltf(path.string());
        else
            (void)loadSceneFile(path.string());
        if (loaded) ++*loaded;
    } catch (const Error&) {
    } catch (const std::exception& e) {
        return std::string("std::exception: ") + e.what();
    } catch (...) {
        return "a non-standard exception";
    }
    return "";
}

struct Input {
    Loader kind;
    fs::path file;
};

std::vector<Input> inputs() {
    std::vector<Input> out;
    for (const char* dir : {"scenes", "scenes/stress", "scenes/audit"})
        for (const auto& e : fs::directory_iterator(kRoot / dir))
            if (e.path().extension() == ".json") out.push_back({Loader::Scene, e.path()});
    for (const auto& e : fs::directory_iterator(kRoot / "experiments" / "configs"))
        if (e.path().extension() == ".json")
            out.push_back(
                {e.path().filename() == "audit.json" ? Loader::AuditCatalog : Loader::Config,
                 e.path()});
    // The shared scene data may be absent (a clone outside the project folder): then the glTF
    // loader is fuzzed only through the regression corpus.
    const fs::path gltf = fs::path(GILAB_SHARED_SCENES_DIR) / "cornell-box" / "cornell_box.gltf";
    if (fs::exists(gltf)) out.push_back({Loader::Gltf, gltf});
    std::sort(out.begin(), out.end(),
              [](const Input& a, const Input& b) { return a.file < b.file; });
    return out;
}

TEST(CpuFuzz, MutatedInputsLoadOrFailWithAClearError) {
    const fs::path dir = fs::temp_directory_path() / ("gilab_fuzz_" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const std::vector<Input> all = inputs();
    ASSERT_GT(all.size(), 10u);
    for (const Input& in : all)
        if (in.kind == Loader::Gltf)
            fs::copy_file(in.file.parent_path() / "cornell_box.bin", dir / "cornell_box.bin",
                          fs::copy_options::overwrite_existing);
    const auto start = std::chrono::steady_clock::now();
    int runs = 0, failures = 0, loaded = 0;
    for (size_t i = 0; i < all.size(); ++i) {
        const Input& in = all[i];
        const std::string original = readAll(in.file);
        std::mt19937 rng(uint32_t(1000 + i));
        const int mutations = in.kind == Loader::Gltf ? 4000 : 300;
        for (int m = 0; m < mutations; ++m) {
            // Everything in the temporary folder (never next to the shipped files: other tests
            // list those folders); the glTF's .bin is copied there once.
            const fs::path target = dir / in.file.filename();
            writeAll(target, mutate(original, rng));
            const std::string what = tryLoad(in.kind, target, &loaded);
            ++runs;
            if (!what.empty()) {
                const fs::path keep =
                    dir / ("crash_" + std::to_string(failures) + "_" + in.file.filename().string());
                fs::copy_file(target, keep, fs::copy_options::overwrite_existing);
                ADD_FAILURE() << in.file << " mutation " << m << ": " << what << " (input kept in "
                              << keep << ")";
                ++failures;
            }
        }
    }
    const double s =
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::printf(
        "%d mutated inputs over %zu files in %.1f s: %d loaded, the others failed with "
        "a gilab::Error; %d failures\n",
        runs, all.size(), s, loaded, failures);
    EXPECT_GT(loaded, 0);  // the mutations are not all rejected at the first byte
    if (failures == 0) fs::remove_all(dir);
}

// Every input that once broke a loader still fails cleanly.
TEST(CpuFuzz, RegressionCorpusFailsCleanly) {
    int files = 0;
    for (const auto& e : fs::directory_iterator(kRoot / "tests" / "fuzz_corpus")) {
        const std::string name = e.path().filename().string();
        Loader kind;
        if (e.path().extension() == ".gltf")
            kind = Loader::Gltf;
        else if (name.rfind("config_", 0) == 0)
            kind = Loader::Config;
        else if (name.rfind("scene_", 0) == 0)
            kind = Loader::Scene;
        else
            continue;
        EXPECT_EQ(tryLoad(kind, e.path()), "") << e.path();
        ++files;
    }
    std::printf("%d corpus files\n", files);
}

}  // namespace
}  // namespace gilab
