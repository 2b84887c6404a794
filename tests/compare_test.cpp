// `gilab compare` (experiments/cli/compare_command.h): values against formulas of
// docs/metrics.md, layer selection, errors, output files, the fixed HDR-FLIP range and the
// zero-median fallback. CPU only.
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>

#include <gtest/gtest.h>

#include "tests/temp_dir.h"

#include "core/image/image_io.h"
#include "experiments/cli/cli.h"
#include "experiments/cli/compare_command.h"
#include "experiments/metrics/metrics.h"

namespace fs = std::filesystem;
using namespace gilab;
using gilab::cli::compareImages;
using gilab::cli::CompareOptions;
using gilab::cli::CompareResult;

namespace {

/** This file's temporary folders (tests/temp_dir.h). */
class TempDir : public test::TempDir {
public:
    TempDir() : test::TempDir("gilab_compare") {}
};

Image makeImage(int w, int h, const std::function<float(int, int, int)>& value) {
    Image image(w, h, 3);
    for (int y = 0; y < h; ++y) {
        for (int x = 0; x < w; ++x) {
            for (int c = 0; c < 3; ++c)
                image.at(x, y, c) = value(x, y, c);
        }
    }
    return image;
}

Image constant(int w, int h, float r, float g, float b) {
    return makeImage(w, h, [&](int, int, int c) { return c == 0 ? r : c == 1 ? g : b; });
}

/** A smooth, varied HDR image. */
Image pattern(int w, int h, float scale = 1.0f) {
    return makeImage(w, h, [&](int x, int y, int c) {
        return scale * (0.05f + 0.9f * float((x * 7 + y * 3 + c * 5) % 17) / 16.0f +
                        (x > w / 2 ? 2.0f : 0.0f));
    });
}

std::string writePlain(const TempDir& dir, const std::string& name, const Image& image) {
    const std::string path = dir.file(name);
    writeExrLayers(path, {{"", image}});
    return path;
}

CompareOptions options(const std::string& test, const std::string& reference) {
    CompareOptions o;
    o.test = test;
    o.reference = reference;
    return o;
}

/** The message of the gilab::Error that compareImages throws ("" if none). */
std::string errorOf(const CompareOptions& o) {
    try {
        compareImages(o);
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

bool contains(const std::string& text, const std::string& part) {
    return text.find(part) != std::string::npos;
}

bool hasNote(const CompareResult& r, const std::string& part) {
    for (const std::string& n : r.notes) {
        if (contains(n, part)) return true;
    }
    return false;
}

}  // namespace

TEST(CpuCompare, IdenticalImagesScoreZero) {
    TempDir dir;
    const std::string a = writePlain(dir, "a.exr", pattern(32, 24));
    const std::string b = writePlain(dir, "b.exr", pattern(32, 24));
    const CompareResult r = compareImages(options(a, b));
    EXPECT_EQ(r.metrics.pixels, 32u * 24u);
    EXPECT_EQ(r.metrics.mse, 0.0);
    EXPECT_EQ(r.metrics.relMse, 0.0);
    EXPECT_EQ(r.metrics.flip.mean, 0.0);     // HDR-FLIP
    EXPECT_EQ(r.metrics.flipLdr.mean, 0.0);  // LDR-FLIP
    EXPECT_EQ(r.metrics.flip.max, 0.0);
    EXPECT_DOUBLE_EQ(r.metrics.ssim, 1.0);
    EXPECT_TRUE(std::isinf(r.metrics.psnrHdr) && r.metrics.psnrHdr > 0);
    EXPECT_TRUE(std::isinf(r.metrics.psnrLdr) && r.metrics.psnrLdr > 0);
    // JSON cannot hold +inf: null, as the runner's metrics.json, with a note.
    EXPECT_TRUE(r.json["metrics"]["psnr_hdr"].is_null());
    EXPECT_EQ(r.json["metrics"]["rel_mse"].get<double>(), 0.0);
    EXPECT_TRUE(hasNote(r, "+inf"));
}

TEST(CpuCompare, KnownDifferenceGivesAnalyticValues) {
    // Reference (0.5, 0.2, 1.0) everywhere; test = 1.1 × reference. docs/metrics.md:
    // MSE = mean (t − r)², relMSE = mean (t − r)² / (r² + 0.01), PSNR = 10 log10(peak² / MSE)
    // with peak = the largest reference value (1.0).
    TempDir dir;
    const std::string ref = writePlain(dir, "ref.exr", constant(24, 20, 0.5f, 0.2f, 1.0f));
    const std::string test =
        writePlain(dir, "test.exr", constant(24, 20, 0.5f * 1.1f, 0.2f * 1.1f, 1.0f * 1.1f));
    const double d[3] = {0.05, 0.02, 0.1}, r[3] = {0.5, 0.2, 1.0};
    double mse = 0.0, rel = 0.0;
    for (int c = 0; c < 3; ++c) {
        mse += d[c] * d[c] / 3.0;
        rel += d[c] * d[c] / (r[c] * r[c] + 0.01) / 3.0;
    }
    ASSERT_NEAR(mse, 0.0043, 1e-12);
    const double psnr = 10.0 * std::log10(1.0 / mse);  // 23.6653 dB

    const CompareResult res = compareImages(options(test, ref));
    EXPECT_NEAR(res.metrics.mse, mse, 1e-5 * mse);
    EXPECT_NEAR(res.metrics.rmse, std::sqrt(mse), 1e-6);
    EXPECT_NEAR(res.metrics.relMse, rel, 1e-5 * rel);
    EXPECT_NEAR(res.metrics.psnrHdrPeak, 1.0, 1e-7);
    EXPECT_NEAR(res.metrics.psnrHdr, psnr, 1e-4);
    EXPECT_NEAR(res.json["metrics"]["rel_mse"].get<double>(), rel, 1e-5 * rel);
    EXPECT_GT(res.metrics.flip.mean, 0.0);
    EXPECT_GT(res.metrics.flipLdr.mean, 0.0);
    EXPECT_TRUE(std::isfinite(res.metrics.psnrLdr));
    // The reference is the second image: swapping changes relMSE (its denominator).
    const CompareResult swapped = compareImages(options(ref, test));
    EXPECT_GT(std::abs(swapped.metrics.relMse - rel), 1e-4);
}

TEST(CpuCompare, MatchesTheRunnersComputeMetrics) {
    // Same library, same pooling: compare's numbers equal computeMetrics' (the runner's
    // metrics.json), also with non-finite pixels, negative values and a mask.
    TempDir dir;
    Image test = pattern(40, 36, 1.3f), ref = pattern(40, 36);
    test.at(3, 4, 1) = std::nanf("");
    ref.at(30, 20, 0) = INFINITY;
    test.at(10, 10, 2) = -0.5f;
    const Image maskImage = makeImage(
        40, 36, [](int x, int y, int) { return (x + y) % 3 == 0 || x < 20 ? 1.0f : 0.0f; });
    CompareOptions o = options(writePlain(dir, "t.exr", test), writePlain(dir, "r.exr", ref));
    o.mask = writePlain(dir, "mask.exr", maskImage);
    const CompareResult r = compareImages(o);

    metrics::MetricOptions mo;
    mo.mask = metrics::Mask::fromImage(maskImage, 0.5f);
    const metrics::MetricSet m = metrics::computeMetrics(test, ref, mo);
    EXPECT_EQ(r.metrics.pixels, m.pixels);
    EXPECT_EQ(r.metrics.regionPixels, m.regionPixels);
    EXPECT_EQ(r.metrics.testNonFinite, 1u);
    EXPECT_EQ(r.metrics.refNonFinite, m.refNonFinite);
    EXPECT_EQ(r.metrics.mse, m.mse);
    EXPECT_EQ(r.metrics.relMse, m.relMse);
    EXPECT_EQ(r.metrics.psnrLdr, m.psnrLdr);
    EXPECT_EQ(r.metrics.psnrHdr, m.psnrHdr);
    EXPECT_EQ(r.metrics.ssim, m.ssim);
    EXPECT_EQ(r.metrics.flip.mean, m.flip.mean);
    EXPECT_EQ(r.metrics.flip.weightedP95, m.flip.weightedP95);
    EXPECT_EQ(r.metrics.flipLdr.mean, m.flipLdr.mean);
    EXPECT_EQ(r.metrics.flipExposures.start, m.flipExposures.start);
    EXPECT_EQ(r.metrics.flipExposures.count, m.flipExposures.count);
    // Input counts over the whole images.
    EXPECT_EQ(r.json["test"]["nan_pixels"].get<size_t>(), 1u);
    EXPECT_EQ(r.json["test"]["negative_pixels"].get<size_t>(), 1u);
    EXPECT_EQ(r.json["reference"]["inf_pixels"].get<size_t>(), 1u);
    EXPECT_TRUE(hasNote(r, "NaN"));
    EXPECT_TRUE(hasNote(r, "negative"));
}

TEST(CpuCompare, SelectsLayersOfMultiLayerExrs) {
    TempDir dir;
    const std::string out = dir.file("out.exr"), ref = dir.file("ref.exr");
    writeExrLayers(out, {{"final", constant(16, 16, 0.5f, 0.5f, 0.5f)},
                         {"indirect", constant(16, 16, 0.2f, 0.2f, 0.2f)},
                         {"direct", constant(16, 16, 0.3f, 0.3f, 0.3f)},
                         {"depth", Image(16, 16, 1, 4.0f)}});
    writeExrLayers(ref, {{"full", constant(16, 16, 0.5f, 0.5f, 0.5f)},
                         {"indirect", constant(16, 16, 0.25f, 0.25f, 0.25f)}});
    CompareOptions o = options(out + ":final", ref + ":full");
    o.metrics = {"relmse"};
    EXPECT_EQ(compareImages(o).metrics.relMse, 0.0);

    o = options(out + ":indirect", ref + ":indirect");
    o.metrics = {"relmse"};
    const CompareResult r = compareImages(o);
    EXPECT_NEAR(r.metrics.relMse, 0.05 * 0.05 / (0.25 * 0.25 + 0.01), 1e-7);
    EXPECT_EQ(r.json["test"]["layer"], "indirect");
    EXPECT_EQ(r.json["test"]["path"], out);

    // No layer named and no plain R,G,B: say which layers exist.
    const std::string noLayer = errorOf(options(out, ref + ":full"));
    EXPECT_TRUE(contains(noLayer, "no plain R,G,B")) << noLayer;
    EXPECT_TRUE(contains(noLayer, "final, indirect, direct, depth")) << noLayer;

    // A plain R,G,B EXR needs no layer.
    const std::string plain = writePlain(dir, "plain.exr", constant(16, 16, 0.5f, 0.5f, 0.5f));
    o = options(plain, ref + ":full");
    o.metrics = {"relmse"};
    EXPECT_EQ(compareImages(o).metrics.relMse, 0.0);
}

TEST(CpuCompare, UnknownLayerListsTheLayers) {
    TempDir dir;
    const std::string out = dir.file("out.exr");
    writeExrLayers(out, {{"final", constant(16, 16, 0.5f, 0.5f, 0.5f)},
                         {"indirect", constant(16, 16, 0.2f, 0.2f, 0.2f)}});
    const std::string e = errorOf(options(out + ":bounce1", out + ":final"));
    EXPECT_TRUE(contains(e, out)) << e;
    EXPECT_TRUE(contains(e, "no layer 'bounce1'")) << e;
    EXPECT_TRUE(contains(e, "layers: final, indirect")) << e;
    const std::string typo = errorOf(options(out + ":indirct", out + ":final"));
    EXPECT_TRUE(contains(typo, "did you mean 'indirect'")) << typo;
    // A layer on a non-EXR file.
    const std::string png = dir.file("a.png");
    writePngTonemapped(png, constant(16, 16, 0.5f, 0.5f, 0.5f), ToneMap{});
    EXPECT_TRUE(contains(errorOf(options(png + ":final", out + ":final")), "need an EXR"));
}

TEST(CpuCompare, ColonInFileNames) {
    TempDir dir;
    // The whole text is an existing file: no layer, even with a ':' in it.
    const std::string odd = writePlain(dir, "odd:final.exr", constant(16, 16, 0.5f, 0.5f, 0.5f));
    cli::ImageArgument a = cli::parseImageArgument(odd);
    EXPECT_EQ(a.path, odd);
    EXPECT_FALSE(a.layer);
    a = cli::parseImageArgument(odd + ":final");
    EXPECT_EQ(a.path, odd);
    EXPECT_EQ(a.layer.value_or("?"), "final");
    a = cli::parseImageArgument("dir:x/file.exr");  // a '/' after the colon: all path
    EXPECT_EQ(a.path, "dir:x/file.exr");
    EXPECT_FALSE(a.layer);
    CompareOptions o = options(odd, odd);
    o.metrics = {"relmse"};
    EXPECT_EQ(compareImages(o).metrics.relMse, 0.0);
}

TEST(CpuCompare, MismatchesAndMissingFilesAreClearErrors) {
    TempDir dir;
    const std::string big = writePlain(dir, "big.exr", constant(32, 32, 1, 1, 1));
    const std::string small = writePlain(dir, "small.exr", constant(16, 24, 1, 1, 1));
    const std::string size = errorOf(options(big, small));
    EXPECT_TRUE(contains(size, "size mismatch")) << size;
    EXPECT_TRUE(contains(size, big) && contains(size, small)) << size;
    EXPECT_TRUE(contains(size, "32x32") && contains(size, "16x24")) << size;

    const std::string layered = dir.file("layered.exr");
    writeExrLayers(layered,
                   {{"final", constant(32, 32, 1, 1, 1)}, {"depth", Image(32, 32, 1, 2.0f)}});
    const std::string channels = errorOf(options(layered + ":depth", big));
    EXPECT_TRUE(contains(channels, "channel mismatch")) << channels;
    EXPECT_TRUE(contains(channels, "layered.exr:depth' (32x32, 1 channel)")) << channels;
    EXPECT_TRUE(contains(channels, big + "' (32x32, 3 channels)")) << channels;

    const std::string missing = errorOf(options(dir.file("nope.exr"), big));
    EXPECT_TRUE(contains(missing, "nope.exr") && contains(missing, "not found")) << missing;
    const std::string missingLayer = errorOf(options(big, dir.file("gone.exr") + ":full"));
    EXPECT_TRUE(contains(missingLayer, "gone.exr") && contains(missingLayer, "not found"));

    std::ofstream(dir.file("garbage.exr")) << "not an image";
    const std::string garbage = errorOf(options(dir.file("garbage.exr"), big));
    EXPECT_TRUE(contains(garbage, "garbage.exr")) << garbage;

    CompareOptions o = options(big, big);
    o.mask = small;
    const std::string mask = errorOf(o);
    EXPECT_TRUE(contains(mask, "mask") && contains(mask, small) && contains(mask, "16x24")) << mask;
}

TEST(CpuCompare, MaskPoolsOverItsPixels) {
    TempDir dir;
    // The test differs from the reference in the right half only.
    const Image ref = constant(32, 32, 0.5f, 0.5f, 0.5f);
    const Image test = makeImage(32, 32, [](int x, int, int) { return x < 16 ? 0.5f : 0.55f; });
    const std::string png = dir.file("left.png");
    writePngTonemapped(png, makeImage(32, 32, [](int x, int, int) { return x < 16 ? 1.f : 0.f; }),
                       ToneMap{});
    CompareOptions o = options(writePlain(dir, "t.exr", test), writePlain(dir, "r.exr", ref));
    o.metrics = {"relmse", "psnr"};
    o.mask = png;
    const CompareResult left = compareImages(o);
    EXPECT_EQ(left.metrics.pixels, 16u * 32u);
    EXPECT_EQ(left.metrics.relMse, 0.0);
    EXPECT_EQ(left.json["mask"]["pixels"].get<size_t>(), 16u * 32u);

    o.mask = writePlain(dir, "right.exr",
                        makeImage(32, 32, [](int x, int, int) { return x >= 16 ? 1.f : 0.f; }));
    const CompareResult right = compareImages(o);
    EXPECT_EQ(right.metrics.pixels, 16u * 32u);
    EXPECT_NEAR(right.metrics.relMse, 0.05 * 0.05 / 0.26, 1e-7);
}

TEST(CpuCompare, OutWritesMapsAndJson) {
    TempDir dir;
    Image test = pattern(32, 24, 1.2f);
    test.at(5, 5, 0) = std::nanf("");
    CompareOptions o =
        options(writePlain(dir, "t.exr", test), writePlain(dir, "r.exr", pattern(32, 24)));
    o.outDir = (dir.path() / "new" / "folder").string();
    const CompareResult r = compareImages(o);
    const fs::path out = o.outDir;
    for (const char* f : {"flip_hdr.exr", "flip_hdr.png", "flip_ldr.exr", "flip_ldr.png",
                          "ssim.exr", "ssim.png", "relmse.exr", "relmse.png", "compare.json"}) {
        EXPECT_TRUE(fs::is_regular_file(out / f)) << f;
    }
    for (const auto& entry : fs::directory_iterator(out)) {
        EXPECT_FALSE(contains(entry.path().filename().string(), ".tmp-")) << entry.path();
    }
    std::ifstream in(out / "compare.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["metrics"]["rel_mse"].get<double>(), r.metrics.relMse);
    EXPECT_EQ(j["metrics"]["flip"]["mean"].get<double>(), r.metrics.flip.mean);
    EXPECT_EQ(j["test"]["nan_pixels"], 1);
    EXPECT_EQ(j["files"].size(), 9u);
    EXPECT_EQ(j["hdr_flip_exposure"]["range"], "automatic");

    // The raw maps: FLIP full size (NaN at the NaN pixel), SSIM (W − 10) × (H − 10), and the
    // per-pixel relMSE map whose mean over the finite pixels is the relMSE.
    const std::vector<ImageLayer> flip = readExrLayers((out / "flip_hdr.exr").string());
    ASSERT_EQ(flip.size(), 1u);
    EXPECT_EQ(flip[0].image.width(), 32);
    EXPECT_TRUE(std::isnan(flip[0].image.at(5, 5, 0)));
    EXPECT_EQ(readExrLayers((out / "ssim.exr").string())[0].image.width(), 22);
    const std::vector<ImageLayer> rel = readExrLayers((out / "relmse.exr").string());
    ASSERT_EQ(rel.size(), 2u);
    EXPECT_EQ(rel[0].name, "rel_mse");
    EXPECT_EQ(rel[1].name, "squared_error");
    double sum = 0.0, sumSq = 0.0;
    size_t n = 0;
    for (size_t p = 0; p < rel[0].image.pixelCount(); ++p) {
        if (!std::isfinite(rel[0].image.data()[p])) continue;
        sum += rel[0].image.data()[p];
        sumSq += rel[1].image.data()[p];
        ++n;
    }
    EXPECT_EQ(n, 32u * 24u - 1u);
    EXPECT_NEAR(sum / double(n), r.metrics.relMse, 1e-6 * r.metrics.relMse);
    EXPECT_NEAR(sumSq / double(n), r.metrics.mse, 1e-6 * r.metrics.mse);
}

TEST(CpuCompare, FlipExposureParsing) {
    EXPECT_EQ(cli::parseFlipExposure("-4:2"), std::make_pair(-4.0, 2.0));
    EXPECT_EQ(cli::parseFlipExposure(" -1.5 : 3 "), std::make_pair(-1.5, 3.0));
    EXPECT_EQ(cli::parseFlipExposure("1:1"), std::make_pair(1.0, 1.0));
    for (const char* bad : {"", "abc", "1", "2:1", "1:2:3", "nan:1", "1:inf", "1:2x", ":2"}) {
        EXPECT_THROW(cli::parseFlipExposure(bad), cli::UsageError) << bad;
    }
}

TEST(CpuCompare, FixedFlipExposureRange) {
    TempDir dir;
    const std::string test = writePlain(dir, "t.exr", pattern(32, 32, 1.25f));
    const std::string refA = writePlain(dir, "a.exr", pattern(32, 32));
    const std::string refB = writePlain(dir, "b.exr", pattern(32, 32, 8.0f));
    CompareOptions o = options(test, refA);
    o.metrics = {"hdr-flip"};
    const CompareResult automatic = compareImages(o);
    const metrics::HdrExposures expected =
        metrics::computeHdrExposures(readExrLayers(refA)[0].image);
    EXPECT_EQ(automatic.metrics.flipExposures.start, expected.start);
    EXPECT_EQ(automatic.metrics.flipExposures.stop, expected.stop);
    EXPECT_FALSE(automatic.exposureFixed);

    o.flipExposure = "-4:2";
    const CompareResult fixedA = compareImages(o);
    EXPECT_TRUE(fixedA.exposureFixed);
    EXPECT_EQ(fixedA.metrics.flipExposures.start, -4.0);
    EXPECT_EQ(fixedA.metrics.flipExposures.stop, 2.0);
    EXPECT_EQ(fixedA.metrics.flipExposures.count, 6);  // max(2, ceil(2 − (−4)))
    EXPECT_EQ(fixedA.json["hdr_flip_exposure"]["range"], "fixed");
    EXPECT_NE(fixedA.metrics.flip.mean, automatic.metrics.flip.mean);

    // The fixed range does not depend on the reference; the automatic one does.
    o.reference = refB;
    const CompareResult fixedB = compareImages(o);
    EXPECT_EQ(fixedB.metrics.flipExposures.start, -4.0);
    EXPECT_EQ(fixedB.metrics.flipExposures.stop, 2.0);
    o.flipExposure.clear();
    EXPECT_NE(compareImages(o).metrics.flipExposures.start, automatic.metrics.flipExposures.start);

    // A malformed range is a usage error: exit code 2.
    o.flipExposure = "2:-4";
    EXPECT_THROW(compareImages(o), cli::UsageError);
    EXPECT_EQ(cli::runCompare(o), cli::kExitUsage);
}

TEST(CpuCompare, MetricSelection) {
    EXPECT_EQ(cli::parseMetricNames({}).size(), 5u);
    EXPECT_EQ(cli::parseMetricNames({" PSNR ", "relmse"}),
              (std::vector<std::string>{"relmse", "psnr"}));
    try {
        cli::parseMetricNames({"flipp"});
        ADD_FAILURE() << "no error";
    } catch (const cli::UsageError& e) {
        EXPECT_TRUE(contains(e.what(), "did you mean 'flip'")) << e.what();
    }
    TempDir dir;
    const std::string a = writePlain(dir, "a.exr", pattern(16, 16));
    CompareOptions o = options(a, a);
    o.metrics = {"relmse", "psnr"};
    const CompareResult r = compareImages(o);
    EXPECT_TRUE(r.json["metrics"].contains("rel_mse"));
    EXPECT_TRUE(r.json["metrics"].contains("psnr_hdr"));
    EXPECT_FALSE(r.json["metrics"].contains("flip"));
    EXPECT_FALSE(r.json["metrics"].contains("ssim"));
    EXPECT_FALSE(r.json.contains("hdr_flip_exposure"));
    EXPECT_TRUE(std::isnan(r.metrics.ssim));
    o.metrics = {"bogus"};
    EXPECT_EQ(cli::runCompare(o), cli::kExitUsage);
}

TEST(CpuCompare, ZeroMedianReferenceUsesTheDocumentedFallback) {
    // A spot-lit reference: 100 of 1024 pixels lit (60 at 1, 40 at 4), the rest black, so its
    // median luminance is 0. docs/metrics.md: c_stop = log2(t⁻¹(0.85) / median of the positive
    // luminances) = log2(2.11887 / 1); c_start = log2(2.11887 / 4).
    TempDir dir;
    const Image ref = makeImage(32, 32, [](int x, int y, int) {
        const int i = y * 32 + x;
        return i < 60 ? 1.0f : i < 100 ? 4.0f : 0.0f;
    });
    const Image test =
        makeImage(32, 32, [&](int x, int y, int c) { return ref.at(x, y, c) * 0.9f + 0.001f; });
    CompareOptions o = options(writePlain(dir, "t.exr", test), writePlain(dir, "r.exr", ref));
    o.metrics = {"hdr-flip"};
    o.outDir = dir.file("out");
    const CompareResult r = compareImages(o);
    EXPECT_TRUE(r.zeroMedianFallback);
    EXPECT_NEAR(r.metrics.flipExposures.stop, std::log2(2.11887), 1e-4);
    EXPECT_NEAR(r.metrics.flipExposures.start, std::log2(2.11887 / 4.0), 1e-4);
    EXPECT_TRUE(hasNote(r, "median luminance is 0")) << r.json["notes"].dump();
    std::ifstream in(fs::path(o.outDir) / "compare.json");
    const nlohmann::json j = nlohmann::json::parse(in);
    EXPECT_EQ(j["hdr_flip_exposure"]["zero_median_fallback"], true);
    EXPECT_TRUE(contains(j["notes"].dump(), "median luminance is 0"));

    // Not with a fixed range, nor for an ordinary reference.
    o.outDir.clear();
    o.flipExposure = "-2:1";
    EXPECT_FALSE(compareImages(o).zeroMedianFallback);
    o.flipExposure.clear();
    o.reference = writePlain(dir, "lit.exr", pattern(32, 32));
    const CompareResult lit = compareImages(o);
    EXPECT_FALSE(lit.zeroMedianFallback);
    EXPECT_FALSE(hasNote(lit, "median"));
    EXPECT_EQ(lit.json["hdr_flip_exposure"]["zero_median_fallback"], false);

    // An all-black reference: range 0 .. 0, said so.
    o.reference = writePlain(dir, "black.exr", constant(32, 32, 0, 0, 0));
    const CompareResult black = compareImages(o);
    EXPECT_EQ(black.metrics.flipExposures.start, 0.0);
    EXPECT_EQ(black.metrics.flipExposures.stop, 0.0);
    EXPECT_TRUE(hasNote(black, "black"));
}

TEST(CpuCompare, PrintsTableOrJson) {
    TempDir dir;
    const std::string a = writePlain(dir, "a.exr", pattern(16, 16));
    const std::string b = writePlain(dir, "b.exr", pattern(16, 16, 1.1f));
    CompareOptions o = options(a, b);
    testing::internal::CaptureStdout();
    EXPECT_EQ(cli::runCompare(o), cli::kExitOk);
    const std::string table = testing::internal::GetCapturedStdout();
    for (const char* row : {"relMSE", "PSNR HDR (dB)", "SSIM", "FLIP (LDR) mean", "HDR-FLIP mean",
                            "HDR-FLIP exposures"}) {
        EXPECT_TRUE(contains(table, row)) << row << "\n" << table;
    }
    o.json = true;
    testing::internal::CaptureStdout();
    EXPECT_EQ(cli::runCompare(o), cli::kExitOk);
    const nlohmann::json j = nlohmann::json::parse(testing::internal::GetCapturedStdout());
    EXPECT_EQ(j["metrics"]["rel_mse"].get<double>(), compareImages(o).metrics.relMse);
}

// Issue 27: every gilab EXR records its pixel footprint; compare warns when they differ.
TEST(CpuCompare, WarnsWhenThePixelFootprintsDiffer) {
    TempDir dir;
    const Image image = pattern(16, 16);
    auto write = [&](const std::string& name, const std::string& filter) {
        const std::string path = dir.file(name);
        ExrAttributes attributes;
        if (!filter.empty()) attributes.push_back({kPixelFilterAttribute, filter});
        writeExrLayers(path, {{"", image}}, attributes);
        EXPECT_EQ(readImageStringAttribute(path, kPixelFilterAttribute), filter);
        return path;
    };
    const std::string center = write("center.exr", "center");
    const std::string box = write("box.exr", "box");
    const std::string unknown = write("unknown.exr", "");

    const CompareResult differ = compareImages(options(center, box));
    ASSERT_EQ(differ.warnings.size(), 1u);
    EXPECT_NE(differ.warnings[0].find("test: center, reference: box"), std::string::npos)
        << differ.warnings[0];
    EXPECT_EQ(differ.json["reference"]["pixel_filter"], "box");
    EXPECT_TRUE(compareImages(options(center, center)).warnings.empty());
    // Not recorded: no check, and null in the JSON
    const CompareResult none = compareImages(options(center, unknown));
    EXPECT_TRUE(none.warnings.empty());
    EXPECT_TRUE(none.json["reference"]["pixel_filter"].is_null());
}
