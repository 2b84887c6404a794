// core/image: Image, EXR layers, tonemapping and colour maths. No GPU needed.
#include <unistd.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <set>

#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include "core/image/color.h"
#include "core/image/image.h"
#include "core/image/image_io.h"
#include "core/util/error.h"

namespace fs = std::filesystem;
using namespace gilab;

namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr float kInf = std::numeric_limits<float>::infinity();

/** A fresh scratch directory per test, removed afterwards. */
class CpuImageFiles : public ::testing::Test {
protected:
    void SetUp() override {
        const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
        m_dir = fs::temp_directory_path() /
                ("gilab_image_test_" + std::to_string(::getpid()) + "_" + info->name());
        fs::remove_all(m_dir);
        fs::create_directories(m_dir);
    }
    void TearDown() override { fs::remove_all(m_dir); }
    std::string path(const std::string& name) const { return (m_dir / name).string(); }
    std::vector<std::string> listDir() const {
        std::vector<std::string> names;
        for (const auto& entry : fs::directory_iterator(m_dir)) {
            names.push_back(entry.path().filename().string());
        }
        return names;
    }
    fs::path m_dir;
};

Image makeRamp(int w, int h, int channels, float offset) {
    Image image(w, h, channels);
    for (size_t i = 0; i < image.values().size(); ++i) {
        image.values()[i] = offset + 0.37f * float(i) - 3.0f;
    }
    return image;
}

bool bitwiseEqual(const Image& a, const Image& b) {
    return a.width() == b.width() && a.height() == b.height() && a.channels() == b.channels() &&
           std::memcmp(a.data(), b.data(), a.values().size() * sizeof(float)) == 0;
}

/** Reads an 8-bit PNG back as bytes. */
std::vector<uint8_t> readPngBytes(const std::string& path, int* channels = nullptr) {
    auto in = OIIO::ImageInput::open(path);
    EXPECT_TRUE(in) << OIIO::geterror();
    if (!in) return {};
    const OIIO::ImageSpec& spec = in->spec();
    if (channels) *channels = spec.nchannels;
    std::vector<uint8_t> bytes(size_t(spec.width) * spec.height * spec.nchannels);
    EXPECT_TRUE(in->read_image(0, 0, 0, spec.nchannels, OIIO::TypeDesc::UINT8, bytes.data()));
    return bytes;
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

}  // namespace

TEST(CpuImage, ConstructsFilled) {
    Image image(3, 2, 4, 1.5f);
    EXPECT_EQ(image.width(), 3);
    EXPECT_EQ(image.height(), 2);
    EXPECT_EQ(image.channels(), 4);
    EXPECT_EQ(image.pixelCount(), 6u);
    EXPECT_EQ(image.values().size(), 24u);
    for (float v : image.values())
        EXPECT_EQ(v, 1.5f);
    image.at(2, 1, 3) = 7.0f;
    EXPECT_EQ(image.values().back(), 7.0f);
    EXPECT_TRUE(Image().empty());
    EXPECT_THROW(Image(-1, 2, 3), Error);
}

TEST(CpuImage, ChannelRange) {
    Image image = makeRamp(4, 3, 5, 0.0f);
    Image mid = image.channelRange(1, 3);
    ASSERT_EQ(mid.channels(), 3);
    for (int y = 0; y < 3; ++y) {
        for (int x = 0; x < 4; ++x) {
            for (int c = 0; c < 3; ++c)
                EXPECT_EQ(mid.at(x, y, c), image.at(x, y, c + 1));
        }
    }
    EXPECT_THROW(image.channelRange(3, 3), Error);
    EXPECT_THROW(image.channelRange(-1, 1), Error);
}

TEST(CpuImage, CountNonFinite) {
    Image image(5, 1, 3, 0.5f);
    auto setPixel = [&](int x, float r, float g, float b) {
        image.at(x, 0, 0) = r;
        image.at(x, 0, 1) = g;
        image.at(x, 0, 2) = b;
    };
    setPixel(0, kNaN, kNaN, kNaN);   // one NaN pixel, not three
    setPixel(1, kNaN, kInf, 1.0f);   // counts as NaN and as Inf
    setPixel(2, -kInf, 0.0f, 0.0f);  // Inf, not negative (only finite values count)
    setPixel(3, -0.25f, 1.0f, -2.0f);
    // pixel 4 stays finite and positive
    FiniteStats stats = countNonFinite(image);
    EXPECT_EQ(stats.nanPixels, 2u);
    EXPECT_EQ(stats.infPixels, 2u);
    EXPECT_EQ(stats.negativePixels, 1u);
    EXPECT_FALSE(stats.allFinite());
    EXPECT_TRUE(countNonFinite(Image(8, 8, 1, 0.0f)).allFinite());
    EXPECT_EQ(countNonFinite(Image(8, 8, 1, -0.0f)).negativePixels, 0u);  // -0 is not < 0
}

TEST_F(CpuImageFiles, ExrRoundTripIsExact) {
    const int w = 7, h = 5;
    Image depth(w, h, 1, 0.0f);
    const float special[] = {1.0e30f,
                             std::numeric_limits<float>::max(),
                             1.0e-30f,
                             std::numeric_limits<float>::min(),
                             1.0e-40f /* denormal */,
                             -0.0f,
                             123456.789f,
                             kInf,
                             kNaN};
    for (size_t i = 0; i < std::size(special); ++i)
        depth.values()[i] = special[i];
    // Written in non-alphabetical order: the order must survive the round trip.
    std::vector<ImageLayer> layers = {{"final", makeRamp(w, h, 3, 0.1f)},
                                      {"depth", depth},
                                      {"albedo_alpha", makeRamp(w, h, 4, -5.0f)},
                                      {"motion", makeRamp(w, h, 2, 9.0f)}};
    const std::string file = path("layers.exr");
    writeExrLayers(file, layers);
    std::vector<ImageLayer> back = readExrLayers(file);
    ASSERT_EQ(back.size(), layers.size());
    for (size_t i = 0; i < layers.size(); ++i) {
        EXPECT_EQ(back[i].name, layers[i].name);
        EXPECT_TRUE(bitwiseEqual(back[i].image, layers[i].image)) << layers[i].name;
    }
    ASSERT_NE(findLayer(back, "depth"), nullptr);
    EXPECT_EQ(findLayer(back, "depth")->at(0, 0, 0), 1.0e30f);
    EXPECT_EQ(findLayer(back, "missing"), nullptr);
}

TEST_F(CpuImageFiles, ExrChannelNamesSeenByOiio) {
    const std::string file = path("names.exr");
    writeExrLayers(file, {{"final", Image(4, 2, 3, 1.0f)},
                          {"depth", Image(4, 2, 1, 2.0f)},
                          {"normal", Image(4, 2, 4, 3.0f)}});
    auto in = OIIO::ImageInput::open(file);
    ASSERT_TRUE(in) << OIIO::geterror();
    const OIIO::ImageSpec& spec = in->spec();
    EXPECT_STREQ(in->format_name(), "openexr");
    EXPECT_EQ(spec.width, 4);
    EXPECT_EQ(spec.height, 2);
    EXPECT_EQ(spec.format, OIIO::TypeDesc::FLOAT);
    std::set<std::string> names(spec.channelnames.begin(), spec.channelnames.end());
    std::set<std::string> expected = {"final.R",  "final.G",  "final.B",  "depth.Z",
                                      "normal.R", "normal.G", "normal.B", "normal.A"};
    EXPECT_EQ(names, expected);
    EXPECT_EQ(spec.get_string_attribute("compression"), "zip");
}

TEST_F(CpuImageFiles, UnprefixedChannelsFormTheEmptyLayer) {
    const std::string file = path("plain.exr");
    Image rgb = makeRamp(3, 3, 3, 0.0f);
    writeExrLayers(file, {{"", rgb}, {"extra", Image(3, 3, 1, 4.0f)}});
    auto in = OIIO::ImageInput::open(file);
    ASSERT_TRUE(in);
    std::set<std::string> names(in->spec().channelnames.begin(), in->spec().channelnames.end());
    EXPECT_EQ(names, (std::set<std::string>{"R", "G", "B", "extra.Z"}));
    in->close();
    std::vector<ImageLayer> back = readExrLayers(file);
    ASSERT_EQ(back.size(), 2u);
    EXPECT_EQ(back[0].name, "");
    EXPECT_TRUE(bitwiseEqual(back[0].image, rgb));
    EXPECT_EQ(back[1].name, "extra");
}

TEST_F(CpuImageFiles, ExrRejectsBadLayers) {
    const std::string file = path("bad.exr");
    std::string message = errorText([&] {
        writeExrLayers(file, {{"final", Image(4, 4, 3)}, {"small_depth", Image(4, 3, 1)}});
    });
    EXPECT_NE(message.find("small_depth"), std::string::npos) << message;
    EXPECT_NE(message.find(file), std::string::npos) << message;
    EXPECT_THROW(writeExrLayers(file, {}), Error);
    EXPECT_THROW(writeExrLayers(file, {{"a", Image(2, 2, 5)}}), Error);
    EXPECT_THROW(writeExrLayers(file, {{"a", Image(2, 2, 3)}, {"a", Image(2, 2, 3)}}), Error);
    EXPECT_FALSE(fs::exists(file));
    EXPECT_TRUE(listDir().empty());
}

TEST_F(CpuImageFiles, ReadErrorsNameTheFile) {
    const std::string missing = path("missing.exr");
    std::string message = errorText([&] { readExrLayers(missing); });
    EXPECT_NE(message.find(missing), std::string::npos) << message;

    const std::string corrupt = path("corrupt.exr");
    {
        std::ofstream out(corrupt, std::ios::binary);
        out << "this is not an EXR file, just some bytes\n";
    }
    message = errorText([&] { readExrLayers(corrupt); });
    EXPECT_NE(message.find(corrupt), std::string::npos) << message;

    // A real EXR cut short: the header or the pixel read fails, still naming the file.
    const std::string truncated = path("truncated.exr");
    writeExrLayers(truncated, {{"final", makeRamp(64, 64, 3, 0.0f)}});
    fs::resize_file(truncated, fs::file_size(truncated) / 2);
    message = errorText([&] { readExrLayers(truncated); });
    EXPECT_NE(message.find(truncated), std::string::npos) << message;

    const std::string png = path("image.png");
    writePngTonemapped(png, Image(2, 2, 3, 0.5f), ToneMap{});
    message = errorText([&] { readExrLayers(png); });
    EXPECT_NE(message.find(png), std::string::npos) << message;
    EXPECT_NE(message.find("not an OpenEXR"), std::string::npos) << message;

    message = errorText([&] { readImageRgb(missing); });
    EXPECT_NE(message.find(missing), std::string::npos) << message;
}

TEST_F(CpuImageFiles, AtomicWriteLeavesNoTemporary) {
    const std::string exr = path("out.exr");
    const std::string png = path("out.png");
    writeExrLayers(exr, {{"final", Image(8, 8, 3, 0.25f)}});
    writeExrLayers(exr, {{"final", Image(8, 8, 3, 0.5f)}});  // overwrite in place
    writePngTonemapped(png, Image(8, 8, 3, 0.25f), ToneMap{});
    std::vector<std::string> names = listDir();
    EXPECT_EQ(std::set<std::string>(names.begin(), names.end()),
              (std::set<std::string>{"out.exr", "out.png"}));
    EXPECT_EQ(readExrLayers(exr)[0].image.at(0, 0, 0), 0.5f);

    // A failed write (no such folder) throws naming the file and leaves nothing behind.
    const std::string nowhere = path("no_such_dir/out.exr");
    std::string message = errorText([&] { writeExrLayers(nowhere, {{"final", Image(2, 2, 3)}}); });
    EXPECT_NE(message.find(nowhere), std::string::npos) << message;
    EXPECT_EQ(listDir().size(), 2u);
}

TEST(CpuColor, SrgbTransferFunctions) {
    EXPECT_EQ(linearToSrgb(0.0f), 0.0f);
    EXPECT_NEAR(linearToSrgb(1.0f), 1.0f, 1e-6f);
    EXPECT_NEAR(linearToSrgb(0.5f), 0.735357f, 1e-5f);
    EXPECT_NEAR(linearToSrgb(0.0031308f), 0.04045f, 1e-5f);  // the pieces meet
    EXPECT_NEAR(linearToSrgb(0.001f), 0.01292f, 1e-7f);      // linear segment
    for (float v = 0.0f; v <= 1.0f; v += 0.01f) {
        EXPECT_NEAR(srgbToLinear(linearToSrgb(v)), v, 1e-5f);
    }
    EXPECT_NEAR(luminance(1.0f, 1.0f, 1.0f), 1.0f, 1e-6f);
    EXPECT_FLOAT_EQ(luminance(glm::vec3(0.0f, 1.0f, 0.0f)), 0.7152f);
}

TEST(CpuColor, AcesCurve) {
    EXPECT_EQ(acesNarkowicz(0.0f), 0.0f);
    EXPECT_EQ(acesNarkowicz(-1.0f), 0.0f);
    EXPECT_NEAR(acesNarkowicz(1.0f), 2.54f / 3.16f, 1e-6f);
    EXPECT_EQ(acesNarkowicz(1.0e30f), 1.0f);
    EXPECT_EQ(acesNarkowicz(std::numeric_limits<float>::max()), 1.0f);
    float previous = 0.0f;
    for (float x = 0.01f; x < 20.0f; x *= 1.1f) {
        EXPECT_GE(acesNarkowicz(x), previous);
        previous = acesNarkowicz(x);
    }
}

TEST(CpuTonemap, KnownValues) {
    Image image(6, 1, 3, 0.0f);
    const float linear[] = {0.0f, 1.0f, 0.5f, 4.0f, -3.0f, 0.18f};
    for (int x = 0; x < 6; ++x) {
        for (int c = 0; c < 3; ++c)
            image.at(x, 0, c) = linear[x];
    }
    Image srgb = tonemapToSrgb(image, ToneMap{});
    EXPECT_EQ(srgb.channels(), 3);
    EXPECT_EQ(srgb.at(0, 0, 0), 0.0f);
    EXPECT_NEAR(srgb.at(1, 0, 0), 1.0f, 1e-6f);
    EXPECT_NEAR(srgb.at(2, 0, 0), 0.735357f, 1e-5f);
    EXPECT_NEAR(srgb.at(3, 0, 0), 1.0f, 1e-6f);  // clamp curve
    EXPECT_EQ(srgb.at(4, 0, 0), 0.0f);           // negative clamps to 0

    // Exposure +1 doubles the linear value before the curve.
    Image quarter(1, 1, 3, 0.25f);
    Image brighter = tonemapToSrgb(quarter, ToneMap{1.0f, ToneMap::Curve::Clamp});
    EXPECT_FLOAT_EQ(brighter.at(0, 0, 0), srgb.at(2, 0, 0));
    Image aces = tonemapToSrgb(Image(1, 1, 3, 1.0f), ToneMap{0.0f, ToneMap::Curve::Aces});
    EXPECT_NEAR(aces.at(0, 0, 0), linearToSrgb(2.54f / 3.16f), 1e-6f);
    EXPECT_THROW(tonemapToSrgb(Image(1, 1, 2), ToneMap{}), Error);
}

TEST_F(CpuImageFiles, PngBytes) {
    Image image(5, 1, 4, 1.0f);  // RGBA in, alpha ignored
    const float linear[] = {0.0f, 1.0f, 0.5f, 0.25f, -1.0f};
    for (int x = 0; x < 5; ++x) {
        for (int c = 0; c < 3; ++c)
            image.at(x, 0, c) = linear[x];
    }
    image.at(3, 0, 1) = 0.5f;  // pixel 3: (0.25, 0.5, 0.25); with +1 EV green saturates
    const std::string file = path("bytes.png");
    writePngTonemapped(file, image, ToneMap{});
    int channels = 0;
    std::vector<uint8_t> bytes = readPngBytes(file, &channels);
    ASSERT_EQ(channels, 3);
    ASSERT_EQ(bytes.size(), 15u);
    EXPECT_EQ(bytes[0], 0);
    EXPECT_EQ(bytes[3], 255);
    EXPECT_EQ(bytes[6], 188);  // 0.5 linear -> 0.7354 sRGB -> 187.5 -> 188
    EXPECT_EQ(bytes[12], 0);

    writePngTonemapped(file, image, ToneMap{1.0f, ToneMap::Curve::Clamp});
    bytes = readPngBytes(file);
    EXPECT_EQ(bytes[6], 255);   // 0.5 * 2 = 1
    EXPECT_EQ(bytes[9], 188);   // 0.25 * 2 = 0.5
    EXPECT_EQ(bytes[10], 255);  // 0.5 * 2 = 1
}

TEST_F(CpuImageFiles, NonFinitePixelsAreMagenta) {
    Image image(4, 1, 3, 0.5f);
    image.at(0, 0, 1) = kNaN;
    image.at(1, 0, 2) = kInf;
    image.at(2, 0, 0) = -kInf;
    const std::string file = path("magenta.png");
    for (auto curve : {ToneMap::Curve::Clamp, ToneMap::Curve::Aces}) {
        writePngTonemapped(file, image, ToneMap{0.0f, curve});
        std::vector<uint8_t> bytes = readPngBytes(file);
        ASSERT_EQ(bytes.size(), 12u);
        for (int x = 0; x < 3; ++x) {
            EXPECT_EQ(bytes[x * 3 + 0], 255) << x;
            EXPECT_EQ(bytes[x * 3 + 1], 0) << x;
            EXPECT_EQ(bytes[x * 3 + 2], 255) << x;
        }
        EXPECT_EQ(bytes[9], bytes[10]);  // the finite grey pixel stays grey
    }
}

TEST_F(CpuImageFiles, ReadImageRgb) {
    const std::string png = path("grey.png");
    writePngTonemapped(png, Image(3, 2, 3, 0.5f), ToneMap{});
    Image fromPng = readImageRgb(png);
    ASSERT_EQ(fromPng.width(), 3);
    ASSERT_EQ(fromPng.height(), 2);
    ASSERT_EQ(fromPng.channels(), 3);
    EXPECT_NEAR(fromPng.at(2, 1, 1), 0.5f, 0.003f);  // decoded back to linear

    const std::string exr = path("plain.exr");
    Image rgb = makeRamp(3, 2, 3, 1.0f);
    writeExrLayers(exr, {{"", rgb}});
    EXPECT_TRUE(bitwiseEqual(readImageRgb(exr), rgb));
    const std::string grey = path("grey.exr");
    writeExrLayers(grey, {{"", Image(2, 2, 1, 0.75f)}});
    Image greyRgb = readImageRgb(grey);
    ASSERT_EQ(greyRgb.channels(), 3);
    EXPECT_EQ(greyRgb.at(1, 1, 2), 0.75f);
}
