// Technique modules (core/technique/modules.h): where gilab looks for them, and the errors for a
// missing path, a file that is not a shared library and a library that is not a gilab module.
// A real module, built out of the tree, is loaded by tests/out_of_tree_test.sh.
#include <cstdlib>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "core/technique/module_abi.h"
#include "core/technique/modules.h"
#include "core/technique/registry.h"
#include "core/util/error.h"
#include "temp_dir.h"

namespace gilab {
namespace {

namespace fs = std::filesystem;

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

TEST(CpuModules, SearchTakesTheOptionThenTheVariableThenTheFolderBesideTheBinary) {
    ::setenv("GILAB_TECHNIQUE_PATH", "/a::/b/gilab-technique-x.so", 1);
    const ModuleSearch s = moduleSearch({"/opt"}, "/usr/local/bin/gilab");
    ::unsetenv("GILAB_TECHNIQUE_PATH");
    ASSERT_EQ(s.explicitPaths.size(), 3u);
    EXPECT_EQ(s.explicitPaths[0], fs::path("/opt"));
    EXPECT_EQ(s.explicitPaths[1], fs::path("/a"));  // the empty entry is skipped
    EXPECT_EQ(s.explicitPaths[2], fs::path("/b/gilab-technique-x.so"));
    const std::string beside = s.besideBinary.string();  // /usr/local/<libdir>/gilab/techniques
    EXPECT_EQ(beside.rfind("/usr/local/lib", 0), 0u) << beside;
    EXPECT_TRUE(beside.ends_with("/gilab/techniques")) << beside;
}

TEST(CpuModules, AFolderGivesItsModulesSortedAndNothingElse) {
    test::TempDir dir;
    for (const char* name :
         {"gilab-technique-b.so", "gilab-technique-a.so", "other.so", "gilab-technique-c.txt"})
        std::ofstream(dir.path() / name) << "x";
    ModuleSearch s;
    s.explicitPaths = {dir.path()};
    const std::vector<fs::path> found = findModules(s);
    ASSERT_EQ(found.size(), 2u);
    EXPECT_EQ(found[0].filename(), "gilab-technique-a.so");
    EXPECT_EQ(found[1].filename(), "gilab-technique-b.so");
}

TEST(CpuModules, AMissingPathIsAnErrorNamingIt) {
    ModuleSearch s;
    s.explicitPaths = {"/no/such/folder"};
    const std::string m = errorOf([&] { findModules(s); });
    EXPECT_NE(m.find("/no/such/folder"), std::string::npos) << m;
    EXPECT_NE(m.find("GILAB_TECHNIQUE_PATH"), std::string::npos) << m;
}

TEST(CpuModules, AFileThatIsNotAModuleIsRefusedByName) {
    test::TempDir dir;
    const fs::path text = dir.path() / "gilab-technique-text.so";
    std::ofstream(text) << "not a shared library";
    std::string m = errorOf([&] { loadTechniqueModule(text); });
    EXPECT_NE(m.find("gilab-technique-text.so: cannot load technique module"), std::string::npos)
        << m;
    // A shared library without gilab_module_abi (the core library itself).
    m = errorOf([&] { loadTechniqueModule(GILAB_CORE_LIBRARY); });
    EXPECT_NE(m.find("not a gilab technique module"), std::string::npos) << m;
}

TEST(CpuModules, TheAbiNamesTheVersionAndTheCommit) {
    const std::string abi = moduleAbi();
    EXPECT_EQ(abi.rfind("gilab ", 0), 0u) << abi;
    EXPECT_NE(abi.find(" ("), std::string::npos) << abi;
}

TEST(CpuModules, BuiltInTechniquesSayWhereTheyComeFrom) {
    EXPECT_EQ(TechniqueRegistry::instance().origin("direct"), "built in");
    EXPECT_EQ(TechniqueRegistry::instance().origin("no_such_technique"), "");
}

}  // namespace
}  // namespace gilab
