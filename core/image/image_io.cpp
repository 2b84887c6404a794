#include "core/image/image_io.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <system_error>

#include <OpenImageIO/imageio.h>

#include "core/image/atomic_write.h"
#include "core/image/color.h"
#include "core/util/error.h"
#include "core/util/strings.h"

namespace gilab {

namespace {

/** Header attribute holding the comma-separated layer order (EXR sorts channel names). */
constexpr const char* kLayerOrderAttribute = "gilab:layerOrder";

const char* const kRgbaSuffixes[] = {"R", "G", "B", "A"};

/** Channel suffixes of a layer with `channels` channels: Z; R,G; R,G,B; R,G,B,A. */
std::vector<std::string> suffixesFor(int channels) {
    if (channels == 1) return {"Z"};
    return std::vector<std::string>(kRgbaSuffixes, kRgbaSuffixes + channels);
}

/** Sort rank of a channel suffix inside one layer. */
int suffixRank(const std::string& suffix) {
    for (int i = 0; i < 4; ++i) {
        if (suffix == kRgbaSuffixes[i]) return i;
    }
    return 4;
}

std::string oiioError(const std::string& text) {
    return text.empty() ? "unknown error" : text;
}

void validateLayers(const std::string& path, const std::vector<ImageLayer>& layers) {
    if (layers.empty()) throw Error(path + ": writeExrLayers called with no layers");
    const int width = layers[0].image.width();
    const int height = layers[0].image.height();
    for (size_t i = 0; i < layers.size(); ++i) {
        const ImageLayer& layer = layers[i];
        const std::string what = path + ": layer '" + layer.name + "'";
        if (layer.image.empty() || layer.image.width() <= 0 || layer.image.height() <= 0) {
            throw Error(what + " is empty");
        }
        if (layer.image.channels() < 1 || layer.image.channels() > 4) {
            throw Error(what + " has " + std::to_string(layer.image.channels()) +
                        " channels; 1 to 4 are supported");
        }
        if (layer.image.width() != width || layer.image.height() != height) {
            throw Error(what + " is " + std::to_string(layer.image.width()) + "x" +
                        std::to_string(layer.image.height()) + " but layer '" + layers[0].name +
                        "' is " + std::to_string(width) + "x" + std::to_string(height));
        }
        for (size_t j = 0; j < i; ++j) {
            if (layers[j].name == layer.name) throw Error(what + " appears twice");
        }
    }
}

}  // namespace

namespace detail {

std::string temporaryPathFor(const std::string& path) {
    return path + ".tmp-" + std::to_string(::getpid());
}

void writeImageAtomic(const std::string& path, const char* formatName, const OIIO::ImageSpec& spec,
                      const void* pixels) {
    const std::string tmp = temporaryPathFor(path);
    auto removeTmp = [&] {
        std::error_code ignored;
        std::filesystem::remove(tmp, ignored);
    };
    auto out = OIIO::ImageOutput::create(formatName);
    if (!out) {
        throw Error(path + ": cannot create a " + formatName +
                    " writer: " + oiioError(OIIO::geterror()));
    }
    if (!out->open(tmp, spec)) {
        std::string message = oiioError(out->geterror());
        removeTmp();
        throw Error(path + ": cannot open for writing: " + message);
    }
    bool ok = out->write_image(spec.format, pixels);
    ok = out->close() && ok;
    if (!ok) {
        std::string message = oiioError(out->geterror());
        removeTmp();
        throw Error(path + ": write failed: " + message);
    }
    std::error_code ec;
    std::filesystem::rename(tmp, path, ec);
    if (ec) {
        removeTmp();
        throw Error(path + ": cannot rename " + tmp + " into place: " + ec.message());
    }
}

}  // namespace detail

void writeExrWithMainImage(const std::string& path, const std::vector<ImageLayer>& layers,
                           const std::string& mainLayer, const ExrAttributes& attributes) {
    const Image* main = findLayer(layers, mainLayer);
    if (!main) throw Error(path + ": no layer '" + mainLayer + "' to write as the main image");
    std::vector<ImageLayer> withMain;
    withMain.reserve(layers.size() + 1);
    withMain.push_back({"", *main});
    withMain.insert(withMain.end(), layers.begin(), layers.end());
    writeExrLayers(path, withMain, attributes);
}

std::string readImageStringAttribute(const std::string& path, const std::string& name) {
    auto in = OIIO::ImageInput::open(path);
    if (!in) {
        (void)OIIO::geterror();  // clear the message: "no attribute" is the answer
        return "";
    }
    const std::string value = in->spec().get_string_attribute(name);
    in->close();
    return value;
}

void writeExrLayers(const std::string& path, const std::vector<ImageLayer>& layers,
                    const ExrAttributes& attributes) {
    validateLayers(path, layers);
    const int width = layers[0].image.width();
    const int height = layers[0].image.height();

    int totalChannels = 0;
    std::vector<std::string> names;
    std::vector<std::string> order;
    for (const ImageLayer& layer : layers) {
        for (const std::string& suffix : suffixesFor(layer.image.channels())) {
            names.push_back(layer.name.empty() ? suffix : layer.name + "." + suffix);
        }
        totalChannels += layer.image.channels();
        order.push_back(layer.name);
    }

    // Interleave every layer's channels into one float32 buffer.
    const size_t pixels = size_t(width) * size_t(height);
    std::vector<float> buffer(pixels * size_t(totalChannels));
    int offset = 0;
    for (const ImageLayer& layer : layers) {
        const int channels = layer.image.channels();
        const float* src = layer.image.data();
        for (size_t p = 0; p < pixels; ++p) {
            float* dst = buffer.data() + p * size_t(totalChannels) + size_t(offset);
            for (int c = 0; c < channels; ++c)
                dst[c] = src[p * size_t(channels) + size_t(c)];
        }
        offset += channels;
    }

    OIIO::ImageSpec spec(width, height, totalChannels, OIIO::TypeDesc::FLOAT);
    spec.channelnames = names;
    spec.alpha_channel = -1;
    spec.z_channel = -1;
    spec.attribute("compression", "zip");
    spec.attribute(kLayerOrderAttribute, joinStrings(order, ","));
    for (const auto& [name, value] : attributes)
        spec.attribute(name, value);
    detail::writeImageAtomic(path, "openexr", spec, buffer.data());
}

std::vector<ImageLayer> readExrLayers(const std::string& path) {
    if (!std::filesystem::exists(path)) throw Error(path + ": file not found");
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(path + ": cannot open: " + oiioError(OIIO::geterror()));
    if (std::string(in->format_name()) != "openexr") {
        throw Error(path + ": not an OpenEXR file (read as " + in->format_name() + ")");
    }
    const OIIO::ImageSpec spec = in->spec();
    if (spec.deep) throw Error(path + ": deep EXR files are not supported");
    const int width = spec.width;
    const int height = spec.height;
    const int channels = spec.nchannels;
    std::vector<float> buffer(size_t(width) * size_t(height) * size_t(channels));
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, buffer.data())) {
        throw Error(path + ": read failed: " + oiioError(in->geterror()));
    }
    in->close();

    // Group channel indices by layer, in order of first appearance.
    struct Group {
        std::string name;
        std::vector<std::pair<std::string, int>> channels;  // suffix, index in the file
    };
    std::vector<Group> groups;
    for (int c = 0; c < channels; ++c) {
        const std::string& full = spec.channel_name(c);
        const size_t dot = full.rfind('.');
        std::string layer = dot == std::string::npos ? "" : full.substr(0, dot);
        std::string suffix = dot == std::string::npos ? full : full.substr(dot + 1);
        auto it = std::find_if(groups.begin(), groups.end(),
                               [&](const Group& g) { return g.name == layer; });
        if (it == groups.end()) it = groups.insert(groups.end(), Group{layer, {}});
        it->channels.emplace_back(suffix, c);
    }

    // Restore the written layer order when the header records it and it matches.
    std::string recorded = spec.get_string_attribute(kLayerOrderAttribute);
    if (groups.size() > 1 && !recorded.empty()) {
        std::vector<std::string> order;
        size_t start = 0;
        while (true) {
            size_t comma = recorded.find(',', start);
            order.push_back(recorded.substr(start, comma - start));
            if (comma == std::string::npos) break;
            start = comma + 1;
        }
        auto rank = [&](const Group& g) {
            return size_t(std::find(order.begin(), order.end(), g.name) - order.begin());
        };
        bool matches = order.size() == groups.size() &&
                       std::all_of(groups.begin(), groups.end(),
                                   [&](const Group& g) { return rank(g) < order.size(); });
        if (matches) {
            std::stable_sort(groups.begin(), groups.end(),
                             [&](const Group& a, const Group& b) { return rank(a) < rank(b); });
        }
    }

    std::vector<ImageLayer> layers;
    for (Group& group : groups) {
        std::stable_sort(
            group.channels.begin(), group.channels.end(),
            [](const auto& a, const auto& b) { return suffixRank(a.first) < suffixRank(b.first); });
        const int count = int(group.channels.size());
        Image image(width, height, count);
        const size_t pixels = image.pixelCount();
        for (size_t p = 0; p < pixels; ++p) {
            for (int c = 0; c < count; ++c) {
                image.data()[p * size_t(count) + size_t(c)] =
                    buffer[p * size_t(channels) + size_t(group.channels[size_t(c)].second)];
            }
        }
        layers.push_back({group.name, std::move(image)});
    }
    return layers;
}

const Image* findLayer(const std::vector<ImageLayer>& layers, const std::string& name) {
    for (const ImageLayer& layer : layers) {
        if (layer.name == name) return &layer.image;
    }
    return nullptr;
}

Image readImageRgb(const std::string& path) {
    if (!std::filesystem::exists(path)) throw Error(path + ": file not found");
    auto in = OIIO::ImageInput::open(path);
    if (!in) throw Error(path + ": cannot open: " + oiioError(OIIO::geterror()));
    const OIIO::ImageSpec spec = in->spec();
    if (spec.deep) throw Error(path + ": deep images are not supported");
    const int channels = spec.nchannels;
    if (channels == 2 || channels < 1) {
        throw Error(path + ": " + std::to_string(channels) + " channels; expected grey or RGB");
    }
    std::vector<float> buffer(size_t(spec.width) * size_t(spec.height) * size_t(channels));
    if (!in->read_image(0, 0, 0, channels, OIIO::TypeDesc::FLOAT, buffer.data())) {
        throw Error(path + ": read failed: " + oiioError(in->geterror()));
    }
    in->close();

    const bool srgb = toLowerAscii(spec.get_string_attribute("oiio:ColorSpace")) == "srgb";
    Image image(spec.width, spec.height, 3);
    const size_t pixels = image.pixelCount();
    for (size_t p = 0; p < pixels; ++p) {
        const float* src = buffer.data() + p * size_t(channels);
        for (int c = 0; c < 3; ++c) {
            float v = src[channels == 1 ? 0 : c];
            image.data()[p * 3 + size_t(c)] = srgb ? srgbToLinear(v) : v;
        }
    }
    return image;
}

}  // namespace gilab
