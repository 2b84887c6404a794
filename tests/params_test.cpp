// core/params: typed technique parameters. No GPU needed.
#include <limits>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "core/params/params.h"
#include "core/util/error.h"
#include "core/util/strings.h"

using namespace gilab;
using nlohmann::json;

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::vector<ParamSpec> sampleSpecs() {
    return {intParam("cone_count", 6, 1, 64, "", "cones per pixel", ParamStage::Rebuild),
            floatParam("cone_angle", 30.0, 0.0, 90.0, "deg", "cone half angle"),
            floatParam("bias", 0.5, -kInf, kInf, "m", "ray offset"),
            boolParam("temporal", true, "accumulate over frames"),
            enumParam("mode", "dense", {"dense", "sparse", "hybrid"}, "voxel storage",
                      ParamStage::Rebuild),
            intParam("steps", 16, 0, kInf, "", "march steps")};
}

ParamSet sampleSet() {
    return ParamSet(sampleSpecs(), "vxgi");
}

template <typename F>
std::string errorText(F&& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "<no gilab::Error thrown>";
}

#define EXPECT_CONTAINS(text, part) \
    EXPECT_NE(std::string(text).find(part), std::string::npos) << "'" << (text) << "'"

}  // namespace

TEST(CpuParams, Defaults) {
    ParamSet p = sampleSet();
    EXPECT_EQ(p.owner(), "vxgi");
    EXPECT_EQ(p.getInt("cone_count"), 6);
    EXPECT_FLOAT_EQ(p.getFloat("cone_angle"), 30.0f);
    EXPECT_FLOAT_EQ(p.getFloat("bias"), 0.5f);
    EXPECT_TRUE(p.getBool("temporal"));
    EXPECT_EQ(p.getEnum("mode"), "dense");
    EXPECT_EQ(p.toString(),
              "cone_count=6 cone_angle=30 bias=0.5 temporal=true mode=dense steps=16");
    EXPECT_EQ(p.specs().size(), 6u);
    EXPECT_EQ(p.spec("cone_angle").unit, "deg");
    EXPECT_TRUE(p.has("mode"));
    EXPECT_FALSE(p.has("nope"));
    EXPECT_TRUE(ParamSet().specs().empty());
}

TEST(CpuParams, SetParsesEachType) {
    ParamSet p = sampleSet();
    p.set("cone_count", "12");
    p.set("cone_angle", "  12.5 ");
    p.set("bias", "-1e-3");
    p.set("mode", "sparse");
    p.set("steps", "+7");
    EXPECT_EQ(p.getInt("cone_count"), 12);
    EXPECT_FLOAT_EQ(p.getFloat("cone_angle"), 12.5f);
    EXPECT_FLOAT_EQ(p.getFloat("bias"), -0.001f);
    EXPECT_EQ(p.getText("bias"), "-0.001");
    EXPECT_EQ(p.getEnum("mode"), "sparse");
    EXPECT_EQ(p.getInt("steps"), 7);
    for (const char* yes : {"true", "1", "on", "ON", "True"}) {
        p.set("temporal", "false");
        p.set("temporal", yes);
        EXPECT_TRUE(p.getBool("temporal")) << yes;
    }
    for (const char* no : {"false", "0", "off", "OFF"}) {
        p.set("temporal", "true");
        p.set("temporal", no);
        EXPECT_FALSE(p.getBool("temporal")) << no;
    }
    EXPECT_EQ(p.getText("temporal"), "false");
    p.set("cone_angle", "0.1");
    EXPECT_EQ(p.getText("cone_angle"), "0.1");  // shortest round trip, not 0.10000000000000001
}

TEST(CpuParams, RangeEdgesAreInclusive) {
    ParamSet p = sampleSet();
    p.set("cone_count", "1");
    EXPECT_EQ(p.getInt("cone_count"), 1);
    p.set("cone_count", "64");
    EXPECT_EQ(p.getInt("cone_count"), 64);
    EXPECT_THROW(p.set("cone_count", "0"), Error);
    EXPECT_THROW(p.set("cone_count", "65"), Error);
    p.set("cone_angle", "0");
    p.set("cone_angle", "90");
    EXPECT_FLOAT_EQ(p.getFloat("cone_angle"), 90.0f);
    EXPECT_THROW(p.set("cone_angle", "90.000001"), Error);
    EXPECT_THROW(p.set("cone_angle", "-0.000001"), Error);
    p.set("steps", "0");
    p.set("steps", "2147483647");
    EXPECT_THROW(p.set("steps", "-1"), Error);
}

TEST(CpuParams, ErrorMessagesNameOwnerKeyAndReason) {
    ParamSet p = sampleSet();
    std::string m = errorText([&] { p.set("cone_count", "1.5"); });
    EXPECT_CONTAINS(m, "vxgi");
    EXPECT_CONTAINS(m, "cone_count");
    EXPECT_CONTAINS(m, "expects an integer");

    m = errorText([&] { p.set("cone_count", "65"); });
    EXPECT_CONTAINS(m, "cone_count");
    EXPECT_CONTAINS(m, "must be in [1, 64]");

    m = errorText([&] { p.set("steps", "-3"); });
    EXPECT_CONTAINS(m, "must be >= 0");

    m = errorText([&] { p.set("cone_angle", "abc"); });
    EXPECT_CONTAINS(m, "cone_angle");
    EXPECT_CONTAINS(m, "expects a number");

    m = errorText([&] { p.set("temporal", "maybe"); });
    EXPECT_CONTAINS(m, "temporal");
    EXPECT_CONTAINS(m, "expects a boolean");

    m = errorText([&] { p.set("mode", "sparce"); });
    EXPECT_CONTAINS(m, "mode");
    EXPECT_CONTAINS(m, "must be one of {dense, sparse, hybrid}");
    EXPECT_CONTAINS(m, "did you mean 'sparse'");

    m = errorText([&] { p.set("cone_cout", "3"); });
    EXPECT_CONTAINS(m, "vxgi");
    EXPECT_CONTAINS(m, "unknown parameter 'cone_cout'");
    EXPECT_CONTAINS(m, "did you mean 'cone_count'");
    EXPECT_CONTAINS(m, "cone_count, cone_angle, bias, temporal, mode, steps");

    m = errorText([&] { p.set("zzzzzzzzzz", "3"); });
    EXPECT_EQ(m.find("did you mean"), std::string::npos) << m;  // nothing close
}

TEST(CpuParams, StrictNumberParsing) {
    ParamSet p = sampleSet();
    for (const char* bad :
         {"1.5", "1e3", "0x10", "", " ", "3a", "--3", "+-3", "9999999999", "1,000"}) {
        EXPECT_THROW(p.set("cone_count", bad), Error) << "'" << bad << "'";
    }
    for (const char* bad : {"nan", "NaN", "inf", "-inf", "infinity", "1e39", "1e400", "0.5x", "",
                            "+", "-", "1..2", "0x1p3", "1e"}) {
        EXPECT_THROW(p.set("bias", bad), Error) << "'" << bad << "'";
    }
    std::string m = errorText([&] { p.set("bias", "nan"); });
    EXPECT_CONTAINS(m, "finite");
    p.set("bias", "1e3");
    EXPECT_FLOAT_EQ(p.getFloat("bias"), 1000.0f);
    p.set("bias", "+.25");
    EXPECT_FLOAT_EQ(p.getFloat("bias"), 0.25f);
    EXPECT_EQ(p.getInt("cone_count"), 6);  // failed sets leave the value alone
}

TEST(CpuParams, GettersRejectWrongTypeAndMissingKeys) {
    ParamSet p = sampleSet();
    std::string m = errorText([&] { p.getInt("cone_angle"); });
    EXPECT_CONTAINS(m, "cone_angle");
    EXPECT_CONTAINS(m, "programming error");
    EXPECT_THROW(p.getFloat("cone_count"), Error);
    EXPECT_THROW(p.getBool("mode"), Error);
    EXPECT_THROW(p.getEnum("temporal"), Error);
    m = errorText([&] { p.getBool("missing"); });
    EXPECT_CONTAINS(m, "missing");
    EXPECT_CONTAINS(m, "programming error");
    EXPECT_THROW(p.getText("missing"), Error);
    EXPECT_THROW(p.spec("missing"), Error);
}

TEST(CpuParams, SetJsonAndApply) {
    ParamSet p = sampleSet();
    p.setJson("cone_count", json(8));
    p.setJson("cone_angle", json(45));
    p.setJson("bias", json(0.125));
    p.setJson("temporal", json(false));
    p.setJson("mode", json("hybrid"));
    EXPECT_EQ(p.getInt("cone_count"), 8);
    EXPECT_FLOAT_EQ(p.getFloat("cone_angle"), 45.0f);
    EXPECT_FLOAT_EQ(p.getFloat("bias"), 0.125f);
    EXPECT_FALSE(p.getBool("temporal"));
    EXPECT_EQ(p.getEnum("mode"), "hybrid");
    p.setJson("cone_count", json("9"));  // strings follow the text rules
    EXPECT_EQ(p.getInt("cone_count"), 9);

    EXPECT_THROW(p.setJson("cone_count", json(2.5)), Error);
    EXPECT_THROW(p.setJson("cone_count", json(true)), Error);
    EXPECT_THROW(p.setJson("mode", json(3)), Error);
    std::string m = errorText([&] { p.setJson("bias", json::array({1, 2})); });
    EXPECT_CONTAINS(m, "bias");
    EXPECT_CONTAINS(m, "array");
    EXPECT_THROW(p.setJson("bias", json(nullptr)), Error);

    p.apply(json{{"cone_count", 4}, {"mode", "sparse"}}, "configs/a.json");
    EXPECT_EQ(p.getInt("cone_count"), 4);
    EXPECT_EQ(p.getEnum("mode"), "sparse");

    // All or nothing: one bad key leaves every value untouched; context leads the message.
    m = errorText([&] { p.apply(json{{"cone_count", 5}, {"steps", -2}}, "configs/b.json"); });
    EXPECT_EQ(m.rfind("configs/b.json: ", 0), 0u) << m;
    EXPECT_CONTAINS(m, "steps");
    EXPECT_EQ(p.getInt("cone_count"), 4);
    m = errorText([&] { p.apply(json{{"cone_cont", 5}}, "configs/c.json"); });
    EXPECT_CONTAINS(m, "configs/c.json");
    EXPECT_CONTAINS(m, "did you mean 'cone_count'");
    EXPECT_THROW(p.apply(json::array(), "x.json"), Error);
}

TEST(CpuParams, JsonRoundTrip) {
    ParamSet p = sampleSet();
    p.set("bias", "0.1");
    p.set("mode", "hybrid");
    p.set("temporal", "off");
    json j = p.toJson();
    EXPECT_EQ(j["cone_count"], 6);
    EXPECT_TRUE(j["cone_count"].is_number_integer());
    EXPECT_TRUE(j["bias"].is_number_float());
    EXPECT_EQ(j["temporal"], false);
    EXPECT_EQ(j["mode"], "hybrid");
    ParamSet q = sampleSet();
    q.apply(json::parse(j.dump()), "round trip");
    EXPECT_TRUE(p.changedKeys(q).empty());
    EXPECT_EQ(q.toString(), p.toString());

    nlohmann::ordered_json ordered = p.toOrderedJson();
    std::vector<std::string> keys;
    for (const auto& item : ordered.items())
        keys.push_back(item.key());
    EXPECT_EQ(keys, (std::vector<std::string>{"cone_count", "cone_angle", "bias", "temporal",
                                              "mode", "steps"}));
}

TEST(CpuParams, ChangedKeysAndRebuild) {
    ParamSet a = sampleSet();
    ParamSet b = sampleSet();
    EXPECT_TRUE(a.changedKeys(b).empty());
    b.set("cone_angle", "10");
    b.set("temporal", "false");
    EXPECT_EQ(a.changedKeys(b), (std::vector<std::string>{"cone_angle", "temporal"}));
    EXPECT_FALSE(a.changesNeedRebuild(a.changedKeys(b)));
    b.set("mode", "sparse");
    EXPECT_EQ(a.changedKeys(b), (std::vector<std::string>{"cone_angle", "temporal", "mode"}));
    EXPECT_TRUE(a.changesNeedRebuild(a.changedKeys(b)));
    b.set("mode", "dense");  // set back to the same value: no change
    EXPECT_FALSE(a.changesNeedRebuild(a.changedKeys(b)));
    EXPECT_TRUE(a.changesNeedRebuild({"unknown_key"}));  // conservative
    EXPECT_FALSE(a.changesNeedRebuild({}));

    ParamSet other({boolParam("extra", false, "x")}, "other");
    EXPECT_EQ(ParamSet().changedKeys(other), (std::vector<std::string>{"extra"}));
}

TEST(CpuParams, HelpTableListsEverything) {
    std::vector<ParamSpec> specs = sampleSpecs();
    std::string help = formatParamHelp(specs);
    for (const ParamSpec& spec : specs) {
        EXPECT_CONTAINS(help, spec.name);
        EXPECT_CONTAINS(help, spec.help);
    }
    EXPECT_CONTAINS(help, "[1, 64]");
    EXPECT_CONTAINS(help, "dense|sparse|hybrid");
    EXPECT_CONTAINS(help, "rebuild");
    EXPECT_CONTAINS(help, "per-frame");
    EXPECT_CONTAINS(help, ">= 0");
    EXPECT_CONTAINS(help, "deg");
    // Aligned: every row starts its "type" column at the same offset.
    size_t column = std::string::npos;
    size_t start = 0;
    while (start < help.size()) {
        size_t end = help.find('\n', start);
        std::string line = help.substr(start, end - start);
        size_t at = line.find_first_not_of(' ', line.find(' '));
        if (column == std::string::npos) column = at;
        EXPECT_EQ(at, column) << line;
        start = end + 1;
    }
    EXPECT_EQ(describeParamRange(specs[2]), "any");
}

TEST(CpuParams, InconsistentSpecsAreRejected) {
    auto fails = [](std::vector<ParamSpec> specs, const std::string& part) {
        std::string m = errorText([&] { ParamSet(std::move(specs), "tech"); });
        EXPECT_CONTAINS(m, "tech");
        EXPECT_CONTAINS(m, part);
    };
    fails({intParam("n", 0, 1, 64, "", "h")}, "must be in [1, 64]");
    fails({floatParam("f", 2.0, 0.0, 1.0, "", "h")}, "must be in [0, 1]");
    fails({boolParam("a", true, "h"), boolParam("a", false, "h")}, "declared twice");
    fails({enumParam("e", "x", {"a", "b"}, "h")}, "must be one of {a, b}");
    fails({enumParam("e", "a", {}, "h")}, "no choices");
    fails({enumParam("e", "a", {"a", "a"}, "h")}, "appears twice");
    fails({intParam("n", 3, 5, 1, "", "h")}, "min > max");
    fails({intParam("n", 3, 0.5, 10, "", "h")}, "not an integer");
    fails({boolParam("CamelCase", true, "h")}, "snake_case");
    fails({boolParam("", true, "h")}, "snake_case");
    ParamSpec bad = boolParam("b", true, "h");
    bad.defaultValue = "yes please";
    fails({bad}, "expects a boolean");
    bad = intParam("n", 1, 0, 2, "", "h");
    bad.choices = {"x"};
    fails({bad}, "only enum");
    bad = floatParam("f", 1.0, 0, 2, "", "h");
    bad.minValue = std::numeric_limits<double>::quiet_NaN();
    fails({bad}, "NaN");
}

// Rules beyond the range are declared in the spec, checked by set() and shown by describe:
// `--set voxel_resolution=65` passed the range [32, 512] and failed only at set-up (issue 48).
TEST(CpuParams, PowerOfTwoOddExtraValuesAndCrossRulesAreDeclared) {
    ParamSet p({requirePowerOfTwo(intParam("res", 64, 32, 512, "voxels", "grid")),
                allowValue(0, requireOdd(intParam("kernel", 5, 1, 9, "", "width"))),
                allowValue(-1, intParam("bounces", -1, 1, 1, "", "-1 or 1")),
                allowValue(0, floatParam("aperture", 0.0, 1.0, 60.0, "deg", "0 = auto")),
                addCrossRule("a multiple of c", intParam("n", 8, 0, 64, "", "count"))},
               "t");
    EXPECT_EQ(errorText([&] { p.set("res", "65"); }),
              "t: parameter 'res' must be a power of two in [32, 512], got 65");
    EXPECT_EQ(errorText([&] { p.set("res", "1024"); }),
              "t: parameter 'res' must be a power of two in [32, 512], got 1024");
    EXPECT_EQ(errorText([&] { p.set("res", "16"); }),
              "t: parameter 'res' must be a power of two in [32, 512], got 16");
    for (const char* ok : {"32", "128", "512"})
        EXPECT_NO_THROW(p.set("res", ok)) << ok;
    EXPECT_EQ(p.getInt("res"), 512);
    EXPECT_EQ(errorText([&] { p.set("kernel", "4"); }),
              "t: parameter 'kernel' must be 0 or odd in [1, 9], got 4");
    EXPECT_THROW(p.set("kernel", "11"), Error);
    for (const char* ok : {"0", "1", "3", "9"})
        EXPECT_NO_THROW(p.set("kernel", ok)) << ok;
    EXPECT_EQ(errorText([&] { p.set("bounces", "0"); }),
              "t: parameter 'bounces' must be -1 or 1, got 0");
    p.set("bounces", "1");
    p.set("bounces", "-1");
    EXPECT_EQ(errorText([&] { p.set("aperture", "0.5"); }),
              "t: parameter 'aperture' must be 0 or in [1, 60], got 0.5");
    p.set("aperture", "0");
    p.set("aperture", "1");
    // `gilab list` and --help show the same words
    const std::vector<ParamSpec>& specs = p.specs();
    EXPECT_EQ(describeParamRange(specs[0]), "power of two in [32, 512]");
    EXPECT_EQ(describeParamRange(specs[1]), "0 or odd in [1, 9]");
    EXPECT_EQ(describeParamRange(specs[2]), "-1 or 1");
    EXPECT_EQ(describeParamRange(specs[3]), "0 or [1, 60]");
    EXPECT_EQ(describeParamRange(specs[4]), "[0, 64]; a multiple of c");
    EXPECT_CONTAINS(formatParamHelp(specs), "power of two in [32, 512]");
    // The rules fit the type
    auto fails = [](ParamSpec spec, const std::string& part) {
        EXPECT_CONTAINS(errorText([&] { ParamSet({spec}, "t"); }), part);
    };
    fails(requirePowerOfTwo(floatParam("f", 1.0, 0.0, 2.0, "", "h")), "only int parameters");
    fails(requireOdd(requirePowerOfTwo(intParam("n", 1, 1, 8, "", "h"))), "leaves only 1");
    fails(allowValue(0.5, intParam("n", 1, 1, 8, "", "h")), "not a finite int");
    fails(allowValue(0, boolParam("b", true, "h")), "only int and float");
    fails(requirePowerOfTwo(intParam("n", 3, 1, 8, "", "h")), "power of two in [1, 8], got 3");
}

TEST(CpuParams, SplitAssignment) {
    EXPECT_EQ(splitAssignment("cone_count=8"),
              std::make_pair(std::string("cone_count"), std::string("8")));
    EXPECT_EQ(splitAssignment(" mode = dense "),
              std::make_pair(std::string("mode"), std::string("dense")));
    EXPECT_EQ(splitAssignment("a=b=c").second, "b=c");
    EXPECT_THROW(splitAssignment("cone_count"), Error);
    EXPECT_THROW(splitAssignment("=8"), Error);
    EXPECT_THROW(splitAssignment("cone_count="), Error);
    std::string m = errorText([] { splitAssignment("oops"); });
    EXPECT_CONTAINS(m, "oops");
}

TEST(CpuParams, StringHelpers) {
    EXPECT_EQ(editDistance("", "abc"), 3u);
    EXPECT_EQ(editDistance("kitten", "sitting"), 3u);
    EXPECT_EQ(editDistance("same", "same"), 0u);
    EXPECT_EQ(findClosestMatch("cone_cnt", {"bias", "cone_count", "cone_angle"}), "cone_count");
    EXPECT_EQ(findClosestMatch("xyz", {"bias", "cone_count"}), "");
    EXPECT_EQ(formatShortest(0.1), "0.1");
    EXPECT_EQ(formatShortest(64.0), "64");
    EXPECT_EQ(trimString("  a b \t\n"), "a b");
}
