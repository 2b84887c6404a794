#pragma once
/**
 * Image files: multi-layer OpenEXR (linear HDR, float32) and tonemapped 8-bit sRGB PNG,
 * both through OpenImageIO. Errors throw gilab::Error naming the file.
 */
#include <string>
#include <vector>

#include "core/image/image.h"

namespace gilab {

/** String header attributes of an EXR ("gilab:..." name, value). */
using ExrAttributes = std::vector<std::pair<std::string, std::string>>;

/**
 * Header attribute naming the pixel footprint an image samples (docs/conventions.md "Camera and
 * images"): "center" (one sample at the pixel centre: every technique, and the reference's centre
 * filter) or "box" (the whole pixel square: the reference's box filter). gilab compare warns
 * when two images' footprints differ.
 */
inline constexpr const char* kPixelFilterAttribute = "gilab:pixelFilter";

/**
 * Writes one EXR holding every layer, channels named "<layer>.R/G/B" ("<layer>.Z" for 1-channel
 * layers, "<layer>.A" for a 4th), float32. Atomic: written to a temporary file, then renamed.
 * Layers have 1 to 4 channels (Z; R,G; R,G,B; R,G,B,A), one size and unique names; a layer
 * named "" is written unprefixed ("R", "G", "B"). ZIP compression (lossless).
 */
void writeExrLayers(const std::string& path, const std::vector<ImageLayer>& layers,
                    const ExrAttributes& attributes = {});
/**
 * Reads a file written by writeExrLayers (or any EXR with "<layer>.<chan>" channel names).
 * Channels are grouped by the text before their last '.'; channels with no '.' (a plain
 * "R", "G", "B" EXR) form the layer named "" (writeExrLayers writes a layer named "" the same
 * way, unprefixed). Layers come back in the order they were written (kept in a header
 * attribute, since EXR itself sorts channel names); in other files, in the order OpenImageIO
 * lists the channels. Within a layer: R, G, B, A, then others. Only the first part is read.
 */
std::vector<ImageLayer> readExrLayers(const std::string& path);
/**
 * writeExrLayers with the layer `mainLayer` also written as the plain "R", "G", "B" channels,
 * so viewers that open the default channels (oiiotool, Blender) show the main image
 * (docs/conventions.md "Output files"). Throws if there is no such layer.
 */
void writeExrWithMainImage(const std::string& path, const std::vector<ImageLayer>& layers,
                           const std::string& mainLayer, const ExrAttributes& attributes = {});
/** A string header attribute of an image file, or "" when it has none (or is not readable). */
std::string readImageStringAttribute(const std::string& path, const std::string& name);
/** The layer named `name`, or nullptr. */
const Image* findLayer(const std::vector<ImageLayer>& layers, const std::string& name);

/**
 * Reads any file OpenImageIO can read as 3-channel linear RGB: grey is replicated, extra
 * channels (alpha) are dropped. Files OpenImageIO tags as sRGB (8-bit PNG, JPEG) are decoded
 * with srgbToLinear; everything else (EXR, HDR) is taken as already linear.
 */
Image readImageRgb(const std::string& path);

/** Tonemapping for previews and LDR metrics only (docs/conventions.md). */
struct ToneMap {
    float exposureEv = 0.0f;  // scale = 2^exposureEv
    enum class Curve { Clamp, Aces } curve = Curve::Clamp;
};
/**
 * Linear RGB -> display sRGB in [0, 1] (3 channels), exposure, curve, sRGB OETF. Input with
 * 1 channel is grey, with 4 the alpha is ignored. Negative values clamp to 0; a pixel with a
 * NaN or Inf in R, G or B becomes magenta (1, 0, 1) so broken pixels are never hidden.
 */
Image tonemapToSrgb(const Image& linearRgb, const ToneMap& tm);
/** Writes an 8-bit sRGB PNG of a linear RGB(A) image (atomic like the EXR). */
void writePngTonemapped(const std::string& path, const Image& linearRgb, const ToneMap& tm);

}  // namespace gilab
