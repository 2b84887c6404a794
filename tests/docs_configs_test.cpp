// Every experiment config shown in the documentation validates (issue 10): the ```json blocks
// of README.md, docs/*.md and each technique's page techniques/<id>/README.md (each is JSON, or
// a "key": value fragment) that hold a "techniques" key, with the page's // comments removed,
// parsed relative to experiments/configs/ (where the docs' relative scene paths point from).
// And every config file, in experiments/configs/ and in each technique's configs/, validates
// relative to its own folder (issue 45: configs moved into technique folders keep their scenes).
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "core/util/error.h"
#include "experiments/runner/experiment_config.h"

namespace gilab {
namespace {
namespace fs = std::filesystem;

struct Block {
    std::string file;
    int line = 0;
    std::string text;
};

std::vector<Block> jsonBlocks(const fs::path& file) {
    std::ifstream in(file);
    std::vector<Block> blocks;
    std::string line;
    int n = 0;
    bool inside = false;
    while (std::getline(in, line)) {
        ++n;
        if (!inside && line.rfind("```json", 0) == 0) {
            inside = true;
            blocks.push_back({file.filename().string(), n + 1, ""});
        } else if (inside && line.rfind("```", 0) == 0) {
            inside = false;
        } else if (inside) {
            // Strip a // comment that is not inside a string (the docs never put // in strings).
            const size_t c = line.find("//");
            blocks.back().text += (c == std::string::npos ? line : line.substr(0, c)) + "\n";
        }
    }
    return blocks;
}

TEST(CpuDocs, EveryConfigShownInTheDocsValidates) {
    const fs::path root(GILAB_SOURCE_DIR);
    std::vector<fs::path> pages{root / "README.md"};
    for (const auto& e : fs::directory_iterator(root / "docs"))
        if (e.path().extension() == ".md") pages.push_back(e.path());
    for (const auto& e : fs::directory_iterator(root / "techniques"))
        if (fs::exists(e.path() / "README.md")) pages.push_back(e.path() / "README.md");
    int configs = 0;
    for (const fs::path& page : pages) {
        for (const Block& b : jsonBlocks(page)) {
            nlohmann::json json;
            try {
                json = nlohmann::json::parse(b.text);
            } catch (const std::exception& e) {
                // A fragment ("key": {...}) is JSON once wrapped in an object.
                try {
                    json = nlohmann::json::parse("{" + b.text + "}");
                } catch (const std::exception&) {
                    ADD_FAILURE() << b.file << ":" << b.line << ": not JSON: " << e.what();
                    continue;
                }
            }
            if (!json.is_object() || !json.contains("techniques")) continue;
            ++configs;
            const std::string where = b.file + ":" + std::to_string(b.line);
            try {
                const exp::ExperimentConfig config = exp::parseExperimentConfig(
                    json, where, (root / "experiments" / "configs").string());
                EXPECT_FALSE(exp::expandRuns(config).empty()) << where;
            } catch (const Error& e) {
                ADD_FAILURE() << where << ": " << e.what();
            }
        }
    }
    EXPECT_GE(configs, 1) << "no config found in the docs: is the test still looking?";
}

TEST(CpuDocs, EveryConfigFileValidatesFromItsFolder) {
    const fs::path root(GILAB_SOURCE_DIR);
    std::vector<fs::path> folders{root / "experiments" / "configs"};
    for (const auto& e : fs::directory_iterator(root / "techniques"))
        if (fs::is_directory(e.path() / "configs")) folders.push_back(e.path() / "configs");
    int files = 0;
    for (const fs::path& folder : folders) {
        for (const auto& e : fs::directory_iterator(folder)) {
            if (e.path().extension() != ".json" || e.path().filename() == "audit.json") continue;
            ++files;
            try {
                const exp::ExperimentConfig config = exp::loadExperimentConfig(e.path().string());
                EXPECT_FALSE(exp::expandRuns(config).empty()) << e.path();
                for (const exp::SceneEntry& scene : config.scenes)
                    if (!scene.path.empty())
                        EXPECT_TRUE(fs::exists(scene.path)) << e.path() << ": " << scene.path;
            } catch (const Error& err) {
                ADD_FAILURE() << e.path() << ": " << err.what();
            }
        }
    }
    EXPECT_GE(files, 10);
}

}  // namespace
}  // namespace gilab
