#include "reference/reference_settings.h"

namespace gilab::ref {

const char* layerName(Layer layer) {
    switch (layer) {
        case Layer::Full:
            return "full";
        case Layer::Emission:
            return "emission";
        case Layer::Direct:
            return "direct";
        case Layer::Bounce1:
            return "bounce1";
        case Layer::Bounce2:
            return "bounce2";
        case Layer::Bounce3Plus:
            return "bounce3plus";
    }
    return "?";
}

const char* pixelFilterName(PixelFilter f) {
    return f == PixelFilter::Center ? "center" : "box";
}

const char* estimatorName(Estimator e) {
    switch (e) {
        case Estimator::Mis:
            return "mis";
        case Estimator::NeeOnly:
            return "nee";
        case Estimator::BsdfOnly:
            return "bsdf";
    }
    return "?";
}

}  // namespace gilab::ref
