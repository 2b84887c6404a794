// `gilab audit` (docs/audit.md): the grading rules, the catalog's checks, the child processes,
// and the quick audit itself (GpuAudit.QuickAuditHasNoRed: every cell of the ctest profile run
// through the gilab binary; any red fails, and the table must be complete).
#include <signal.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/technique/frame_harness.h"
#include "core/technique/registry.h"
#include "core/util/embedded_text.h"
#include "core/util/error.h"
#include "experiments/audit/audit.h"
#include "experiments/audit/child_process.h"
#include "temp_dir.h"

namespace gilab::audit {
namespace {

namespace fs = std::filesystem;

CellResult okCell() {
    CellResult c;
    c.technique = "vct";
    c.caseName = "x";
    c.outcome = "ok";
    c.energyRatio = 0.9;
    c.peakRatio = 1.0;
    return c;
}

/** The grade of a clean cell after `change`, with no case-specific rule. */
template <class Change>
Grade grade(Change change) {
    CellResult c = okCell();
    change(c);
    gradeCell(c, AuditCase{});
    return c.grade;
}

TEST(CpuAudit, CleanCellIsGreen) {
    CellResult c = okCell();
    gradeCell(c, AuditCase{});
    EXPECT_EQ(c.grade, Grade::Green) << c.reason;
}

TEST(CpuAudit, DefectsAreRed) {
    EXPECT_EQ(grade([](CellResult& c) { c.nanPixels = 1; }), Grade::Red);
    EXPECT_EQ(grade([](CellResult& c) { c.infPixels = 3; }), Grade::Red);
    EXPECT_EQ(grade([](CellResult& c) { c.negativePixels = 1; }), Grade::Red);
    EXPECT_EQ(grade([](CellResult& c) { c.validationMessages = 1; }), Grade::Red);
    EXPECT_EQ(grade([](CellResult& c) { c.energyRatio = 10.5; }), Grade::Red);
    EXPECT_EQ(grade([](CellResult& c) { c.energyRatio = std::nan(""); }), Grade::Red);
    EXPECT_EQ(grade([](CellResult& c) { c.peakRatio = 101.0; }), Grade::Red);
    EXPECT_EQ(grade([](CellResult& c) { c.scaleRatio = 1.11; }), Grade::Red);
    EXPECT_EQ(grade([](CellResult& c) {
                  c.outcome = "crash";
                  c.message = "killed by signal Segmentation fault";
              }),
              Grade::Red);
    EXPECT_EQ(grade([](CellResult& c) {
                  c.outcome = "error";
                  c.message = "internal error: vector::_M_range_check";
              }),
              Grade::Red);
}

TEST(CpuAudit, WeaknessesAreAmber) {
    EXPECT_EQ(grade([](CellResult& c) { c.energyRatio = 0.3; }), Grade::Amber);
    EXPECT_EQ(grade([](CellResult& c) { c.energyRatio = 3.0; }), Grade::Amber);
    EXPECT_EQ(grade([](CellResult& c) { c.peakRatio = 5.0; }), Grade::Amber);
    EXPECT_EQ(grade([](CellResult& c) { c.clampedPercent = 40.0; }), Grade::Amber);
    EXPECT_EQ(grade([](CellResult& c) { c.leak = 0.02; }), Grade::Amber);
    EXPECT_EQ(grade([](CellResult& c) { c.scaleRatio = 1.05; }), Grade::Amber);
    EXPECT_EQ(grade([](CellResult& c) {
                  c.outcome = "error";
                  c.message = "vkAllocateMemory: VK_ERROR_OUT_OF_DEVICE_MEMORY";
              }),
              Grade::Amber);
    EXPECT_EQ(grade([](CellResult& c) { c.outcome = "timeout"; }), Grade::Amber);
    // Within the green bands
    EXPECT_EQ(grade([](CellResult& c) { c.energyRatio = 1.9; }), Grade::Green);
    EXPECT_EQ(grade([](CellResult& c) { c.scaleRatio = 1.01; }), Grade::Green);
    EXPECT_EQ(grade([](CellResult& c) { c.leak = 0.005; }), Grade::Green);
}

TEST(CpuAudit, DocumentedFailureTurnsAnEnergyExcessAmberButNotANaN) {
    AuditCase leak;
    leak.documentedFailure = "light leaks through thin walls";
    CellResult c = okCell();
    c.energyRatio = 40.0;
    gradeCell(c, leak);
    EXPECT_EQ(c.grade, Grade::Amber);
    EXPECT_NE(c.reason.find("light leaks"), std::string::npos) << c.reason;
    c.nanPixels = 2;
    gradeCell(c, leak);
    EXPECT_EQ(c.grade, Grade::Red);
}

// Two techniques' declarations, embedded as gilab_add_technique embeds known_weaknesses.json.
const EmbeddedTextRegistration kDeclared{
    "declaring/known_weaknesses.json",
    R"({"comment": "test", "cases": {"stiff": "constant term, ignores the lights"}})"};
const EmbeddedTextRegistration kMalformed{"malformed/known_weaknesses.json",
                                          R"({"cases": {"stiff": ""}})"};

TEST(CpuAudit, DeclaredWeaknessTurnsAMeasuredRedIntoDeclaredButNeverADefect) {
    AuditCase stiff;
    stiff.name = "stiff";
    CellResult c = okCell();
    c.technique = "declaring";
    c.energyRatio = 40.0;  // a blow-up: red unless declared
    gradeCell(c, stiff);
    EXPECT_EQ(c.grade, Grade::Declared) << c.reason;
    EXPECT_EQ(c.declared, "constant term, ignores the lights");
    EXPECT_NE(c.reason.find("40"), std::string::npos) << c.reason;  // the number stays

    AuditCase other;
    other.name = "other";  // a case it does not declare
    c.declared.clear();
    gradeCell(c, other);
    EXPECT_EQ(c.grade, Grade::Red);

    c.technique = "vct";  // declares nothing
    gradeCell(c, stiff);
    EXPECT_EQ(c.grade, Grade::Red);

    c.technique = "declaring";  // a defect in a declared case stays red
    for (auto defect : std::vector<void (*)(CellResult&)>{
             [](CellResult& x) { x.nanPixels = 1; },
             [](CellResult& x) { x.validationMessages = 1; },
             [](CellResult& x) { x.outcome = "crash"; },
             [](CellResult& x) { x.outcome = "error", x.message = "boom"; }}) {
        CellResult d = c;
        defect(d);
        gradeCell(d, stiff);
        EXPECT_EQ(d.grade, Grade::Red) << d.reason;
    }
}

TEST(CpuAudit, MalformedDeclarationNamesTheFile) {
    try {
        declaredWeaknesses("malformed");
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("malformed/known_weaknesses.json"), std::string::npos)
            << e.what();
        EXPECT_NE(std::string(e.what()).find("stiff"), std::string::npos) << e.what();
    }
    EXPECT_TRUE(declaredWeaknesses("vct").empty());
}

TEST(CpuAudit, ADeclaredCaseMissingFromTheCatalogStopsTheAuditBeforeAnyCell) {
    test::TempDir dir;
    AuditOptions o;
    o.techniques = {"declaring"};  // declares "stiff", which audit.json does not have
    o.outDir = (dir.path() / "audit").string();
    o.quiet = true;
    try {
        runAudit(o);
        FAIL() << "no error";
    } catch (const Error& e) {
        EXPECT_NE(std::string(e.what()).find("declares case \"stiff\""), std::string::npos)
            << e.what();
    }
    EXPECT_FALSE(fs::exists(dir.path() / "audit")) << "a cell ran before the check";
}

TEST(CpuAudit, RefusalIsGreenOnlyWhenItNamesTheParameter) {
    AuditCase p;
    p.parameterCase = true;
    p.params["vct"]["voxel_resolution"] = "16";
    CellResult c = okCell();
    c.outcome = "refused";
    c.message =
        "x.json: \"techniques[0].params.voxel_resolution\": out of range: must be in [32, "
        "512] (got 16)";
    gradeCell(c, p);
    EXPECT_EQ(c.grade, Grade::Green) << c.reason;
    c.message = "internal error";
    gradeCell(c, p);
    EXPECT_EQ(c.grade, Grade::Red) << c.reason;
    // A shared-pass parameter is named without its "shared." prefix
    p.params["vct"] = {{"shared.pcf_radius", "99"}};
    c.message = "x.json: \"techniques[0].shared.pcf_radius\": out of range";
    gradeCell(c, p);
    EXPECT_EQ(c.grade, Grade::Green) << c.reason;
}

TEST(CpuAudit, UnsupportedAndNotApplicableAreNotGraded) {
    CellResult c;
    c.outcome = "unsupported";
    c.message = "no spot or directional light";
    gradeCell(c, AuditCase{});
    EXPECT_EQ(c.grade, Grade::Skipped);
    c.outcome = "n/a";
    gradeCell(c, AuditCase{});
    EXPECT_EQ(c.grade, Grade::NotApplicable);
}

TEST(CpuAudit, PathTracerChecks) {
    ReferenceResult r;
    r.relError = 0.05;
    r.pixels = 1000;
    gradeReference(r);
    EXPECT_EQ(r.grade, Grade::Green);
    r.nonFiniteSamples = 1;
    gradeReference(r);
    EXPECT_EQ(r.grade, Grade::Red);
    r.nonFiniteSamples = 0;
    r.fireflyPixels = 5;  // 0.5 % of the pixels
    gradeReference(r);
    EXPECT_EQ(r.grade, Grade::Amber);
    r.fireflyPixels = 0;
    r.scaleRatio = 1.012;  // the 1 mm box before the ray offsets scaled with the scene
    r.scaleZ = 4.0;
    gradeReference(r);
    EXPECT_EQ(r.grade, Grade::Amber);
    r.scaleZ = 6.0;
    gradeReference(r);
    EXPECT_EQ(r.grade, Grade::Red);
    r.scaleRatio = 1.03;
    r.scaleZ = 1.0;
    gradeReference(r);
    EXPECT_EQ(r.grade, Grade::Red);
}

std::string catalogError(const std::string& text) {
    test::TempDir dir("gilab_audit_catalog");
    const fs::path file = dir.path() / "audit.json";
    std::ofstream(file) << text;
    try {
        loadCatalog(file.string());
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

const char* kProfiles =
    R"("profiles": {"quick": {"resolution": [8, 8], "spp": 4, "max_bounces": 2,
     "voxel_resolution": 32}, "full": {"resolution": [8, 8], "spp": 4, "max_bounces": 2,
     "voxel_resolution": 32}})";

TEST(CpuAudit, CatalogErrorsNameTheFileAndTheKey) {
    std::string e = catalogError(std::string("{") + kProfiles + R"(, "cases": [{"name": "a",
        "what": "w", "scene": "builtin", "colour": 1}]})");
    EXPECT_NE(e.find("audit.json"), std::string::npos) << e;
    EXPECT_NE(e.find("colour"), std::string::npos) << e;
    e = catalogError(std::string("{") + kProfiles + R"(, "cases": [
        {"name": "a", "what": "w", "scene": "builtin"}, {"name": "a", "what": "w", "scene": "builtin"}]})");
    EXPECT_NE(e.find("duplicate case name"), std::string::npos) << e;
    e = catalogError(std::string("{") + kProfiles + R"(, "cases": [
        {"name": "a", "what": "w", "scene": "missing.json"}]})");
    EXPECT_NE(e.find("no such scene file"), std::string::npos) << e;
    e = catalogError(std::string("{") + kProfiles + R"(, "cases": [
        {"name": "a", "what": "w", "scene": "builtin", "scale_group": "g"}]})");
    EXPECT_NE(e.find("scale group \"g\""), std::string::npos) << e;
    e = catalogError(std::string("{") + kProfiles + R"(, "cases": [
        {"name": "a", "what": "w", "scene": "builtin", "parameter_case": true}]})");
    EXPECT_NE(e.find("needs \"params\""), std::string::npos) << e;
}

// The shipped catalog: every scene exists (checked by loadCatalog), every parameter it sets
// exists in that technique (a typo would make the case test nothing), and the quick profile
// covers a case of each kind.
TEST(CpuAudit, ShippedCatalogNamesRealParameters) {
    const Catalog c =
        loadCatalog(std::string(GILAB_SOURCE_DIR) + "/experiments/configs/audit.json");
    EXPECT_GE(c.cases.size(), 20u);
    size_t quick = 0;
    for (const AuditCase& a : c.cases) {
        quick += a.quick;
        for (const auto& [technique, params] : a.params) {
            ASSERT_NE(TechniqueRegistry::instance().find(technique), nullptr) << technique;
            const ParamSet defaults = TechniqueRegistry::instance().defaultParams(technique);
            const ParamSet shared = defaultSharedParams();
            for (const auto& [key, value] : params) {
                if (key.rfind("shared.", 0) == 0)
                    EXPECT_TRUE(shared.has(key.substr(7))) << a.name << ": " << key;
                else
                    EXPECT_TRUE(defaults.has(key)) << a.name << ": " << technique << "." << key;
            }
        }
    }
    EXPECT_GE(quick, 10u);
}

TEST(CpuAudit, ChildProcessCrashTimeoutAndExitCodeAreReported) {
    test::TempDir dir("gilab_audit_child");
    const fs::path log = dir.path() / "log.txt";
    ChildExit e =
        runChild({"/bin/sh", "-c", "echo 'gilab: error: x.json: bad'; exit 1"}, log, 10, nullptr);
    EXPECT_TRUE(e.exited);
    EXPECT_EQ(e.code, 1);
    EXPECT_EQ(lastErrorLine(log), "x.json: bad");
    e = runChild({"/bin/sh", "-c", "kill -SEGV $$"}, log, 10, nullptr);
    EXPECT_FALSE(e.exited);
    EXPECT_EQ(e.signal, SIGSEGV);
    e = runChild({"/bin/sh", "-c", "sleep 30"}, log, 0.3, nullptr);
    EXPECT_TRUE(e.timedOut);
    EXPECT_LT(e.seconds, 15.0);
    e = runChild({"/nonexistent/dir/x"}, dir.path() / "sub" / "log.txt", 10, nullptr);
    EXPECT_TRUE(e.exited);
    EXPECT_EQ(e.code, 127);
    EXPECT_NE(lastErrorLine(dir.path() / "sub" / "log.txt").find("cannot run"), std::string::npos);
}

// The command's exit codes: 6 when a cell is red (here a scene whose glTF is missing: the
// reference and the run fail), 1 for an unknown case; the table is written either way.
TEST(GpuAudit, ExitCodeSixOnRedAndOneOnBadInput) {
    test::TempDir dir("gilab_audit_exit");
    std::ofstream(dir.path() / "broken.json") << R"({"gltf": "missing.gltf"})";
    std::ofstream(dir.path() / "catalog.json") << std::string("{") + kProfiles + R"(,
        "cases": [{"name": "broken", "what": "a missing glTF", "scene": "broken.json"}]})";
    const fs::path out = dir.path() / "out";
    ChildExit e =
        runChild({GILAB_EXECUTABLE, "audit", "--catalog", (dir.path() / "catalog.json").string(),
                  "--techniques", "direct", "--out", out.string(), "--no-validation"},
                 dir.path() / "log.txt", 300, nullptr);
    EXPECT_TRUE(e.exited);
    EXPECT_EQ(e.code, 6);
    const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "audit.json"));
    ASSERT_EQ(j["cells"].size(), 1u);
    EXPECT_EQ(j["cells"][0]["grade"], "red");
    EXPECT_NE(j["cells"][0]["reason"].get<std::string>().find("missing.gltf"), std::string::npos)
        << j["cells"][0].dump();
    EXPECT_EQ(j["references"][0]["grade"], "red");
    e = runChild({GILAB_EXECUTABLE, "audit", "--cases", "no_such_case", "--out", out.string()},
                 dir.path() / "log2.txt", 60, nullptr);
    EXPECT_EQ(e.code, 1);
    EXPECT_NE(lastErrorLine(dir.path() / "log2.txt").find("unknown case \"no_such_case\""),
              std::string::npos);
}

// SIGTERM (a scheduler's time limit) or Ctrl-C: the audit stops its running cell, keeps the table
// so far (complete: false) and exits 130.
TEST(GpuAudit, InterruptKeepsThePartialTable) {
    test::TempDir dir("gilab_audit_interrupt");
    const fs::path out = dir.path() / "out";
    // The direct baseline's cells stop within a second of the signal; its 18 quick cases take
    // far longer than 8 s in all
    const ChildExit e = runChild(
        {GILAB_EXECUTABLE, "audit", "--quick", "--techniques", "direct", "--out", out.string()},
        dir.path() / "log.txt", 8.0, nullptr);
    EXPECT_TRUE(e.timedOut);
    EXPECT_TRUE(e.exited) << "killed by signal " << e.signal;
    EXPECT_EQ(e.code, 130);
    const nlohmann::json j = nlohmann::json::parse(std::ifstream(out / "audit.json"));
    EXPECT_FALSE(j["complete"].get<bool>());
    EXPECT_LT(j["references"].size(), 18u);
    EXPECT_GE(j["references"].size(), 1u);
}

// The ctest profile of `gilab audit --quick` through the gilab binary: no red, and a complete
// table (a reference row per case, a cell per technique x case).
TEST(GpuAudit, QuickAuditHasNoRed) {
    test::TempDir dir("gilab_audit_quick");
    AuditOptions o;
    o.quick = true;
    o.outDir = (dir.path() / "audit").string();
    o.executable = GILAB_EXECUTABLE;
    o.quiet = true;
    const AuditSummary s = runAudit(o);
    for (const CellResult& c : s.cells)
        EXPECT_NE(c.grade, Grade::Red) << c.caseName << " / " << c.technique << ": " << c.reason;
    for (const ReferenceResult& r : s.references)
        EXPECT_NE(r.grade, Grade::Red) << r.caseName << " / path tracer: " << r.reason;
    EXPECT_EQ(s.red, 0u);
    EXPECT_FALSE(s.cancelled);
    const nlohmann::json j =
        nlohmann::json::parse(std::ifstream(dir.path() / "audit" / "audit.json"));
    EXPECT_TRUE(j["complete"].get<bool>());
    const size_t techniques = TechniqueRegistry::instance().list().size();
    EXPECT_GE(j["references"].size(), 10u);
    EXPECT_EQ(j["cells"].size(), j["references"].size() * techniques);
    for (const auto& cell : j["cells"]) {
        if (cell["outcome"] != "ok") continue;
        EXPECT_EQ(cell["nan_pixels"], 0) << cell.dump();
        EXPECT_EQ(cell["validation_messages"], 0) << cell.dump();
        EXPECT_GT(cell["setup_ms"].get<double>(), 0.0) << cell.dump();
    }
    // The scale cases: the same image at 1 mm and 5 km, for the path tracer and every technique
    for (const auto& r : j["references"]) {
        if (r["case"] != "box_1mm" && r["case"] != "box_5km") continue;
        EXPECT_NEAR(r["scale_ratio"].get<double>(), 1.0, 0.002) << r.dump();
    }
    EXPECT_TRUE(fs::exists(dir.path() / "audit" / "audit.html"));
    EXPECT_TRUE(fs::exists(dir.path() / "audit" / "audit.md"));
}

}  // namespace
}  // namespace gilab::audit
