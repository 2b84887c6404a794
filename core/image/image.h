#pragma once
/**
 * CPU-side float images: the one type every output, reference and metric works on.
 * Linear HDR, row-major, row 0 = top of the image, channels interleaved.
 */
#include <cstddef>
#include <string>
#include <vector>

namespace gilab {

class Image {
public:
    Image() = default;
    Image(int width, int height, int channels, float fill = 0.0f);

    int width() const { return m_width; }
    int height() const { return m_height; }
    int channels() const { return m_channels; }
    bool empty() const { return m_data.empty(); }
    size_t pixelCount() const { return size_t(m_width) * size_t(m_height); }

    float& at(int x, int y, int c) { return m_data[index(x, y, c)]; }
    float at(int x, int y, int c) const { return m_data[index(x, y, c)]; }
    float* data() { return m_data.data(); }
    const float* data() const { return m_data.data(); }
    std::vector<float>& values() { return m_data; }
    const std::vector<float>& values() const { return m_data; }

    /** The first `count` channels starting at `first`, as a new image. */
    Image channelRange(int first, int count) const;

private:
    size_t index(int x, int y, int c) const {
        return (size_t(y) * size_t(m_width) + size_t(x)) * size_t(m_channels) + size_t(c);
    }
    int m_width = 0;
    int m_height = 0;
    int m_channels = 0;
    std::vector<float> m_data;
};

/** Non-finite pixel counts of one image; a pixel counts once if any channel is NaN (or Inf). */
struct FiniteStats {
    size_t nanPixels = 0;
    size_t infPixels = 0;
    size_t negativePixels = 0;  // any channel < 0 (radiance must not be negative)
    bool allFinite() const { return nanPixels == 0 && infPixels == 0; }
};
FiniteStats countNonFinite(const Image& image);

/** Mean and maximum Rec.709 luminance of an RGB(A) image's finite pixels (0 when empty). */
double meanLuminance(const Image& rgb);
double maxLuminance(const Image& rgb);

/** A named image in a multi-layer file, e.g. {"final", rgb}; channel names follow EXR (R,G,B / Z).
 */
struct ImageLayer {
    std::string name;
    Image image;
};

}  // namespace gilab
