#include "experiments/runner/reference_set.h"

#include <cmath>

#include "core/technique/technique.h"

namespace gilab::exp {
namespace {

void addInto(Image& sum, const Image& term) {
    if (sum.empty()) {
        sum = term;
        return;
    }
    for (size_t i = 0; i < sum.values().size(); ++i)
        sum.values()[i] += term.values()[i];
}

void addSquaredInto(Image& sum, const Image& sigma) {
    if (sum.empty()) sum = Image(sigma.width(), sigma.height(), sigma.channels());
    for (size_t i = 0; i < sum.values().size(); ++i)
        sum.values()[i] += sigma.values()[i] * sigma.values()[i];
}

void sqrtInPlace(Image& image) {
    for (float& v : image.values())
        v = std::sqrt(v);
}

}  // namespace

ReferenceSet::ReferenceSet(ref::ReferenceResult result)
    : m_result(std::move(result)),
      m_mean(ref::meanLayers(m_result.acc)),
      m_stdError(ref::stdErrorLayers(m_result.acc)) {}

const Image& ReferenceSet::mean(ref::Layer layer) const {
    return m_mean[size_t(layer)].image;
}
const Image& ReferenceSet::stdError(ref::Layer layer) const {
    return m_stdError[size_t(layer)].image;
}

const metrics::NoiseFloorSamples& ReferenceSet::noiseFloor(
    const std::string& basis, const Image& image, const metrics::MetricOptions& options) const {
    const std::string key = basis + (options.resampleFlip ? "|flip" : "");
    auto it = m_noiseFloors.find(key);
    if (it == m_noiseFloors.end())
        it = m_noiseFloors.emplace(key, metrics::computeNoiseFloor(image, options)).first;
    return it->second;
}

int ReferenceSet::maxBounces() const {
    const auto& sidecar = m_result.sidecar;
    if (sidecar.is_object() && sidecar.contains("settings") && sidecar["settings"].is_object() &&
        sidecar["settings"].contains("max_bounces") &&
        sidecar["settings"]["max_bounces"].is_number_integer())
        return sidecar["settings"]["max_bounces"].get<int>();
    return kAllBounces;
}

const std::optional<metrics::MetricSet>& ReferenceSet::bounceFloor(
    int bounces, const metrics::MetricOptions& options) const {
    const std::pair<int, bool> key{bounces, options.resampleFlip};
    auto it = m_bounceFloors.find(key);
    if (it != m_bounceFloors.end()) return it->second;
    std::optional<metrics::MetricSet> floor;
    const int max = maxBounces();
    // match(b) for b >= max_bounces holds every bounce the path tracer traced: the full image
    // (up to float rounding of the layer sums), so there is no floor below it to report.
    if (bounces != kAllBounces && bounces < 3 && (max == kAllBounces || max > bounces)) {
        const MatchedReference m = match(bounces);
        floor = metrics::computeMetrics(m.final, m.full, options);
    }
    return m_bounceFloors.emplace(key, std::move(floor)).first->second;
}

MatchedReference ReferenceSet::match(int bounces) const {
    using ref::Layer;
    MatchedReference m;
    m.set = this;
    m.full = mean(Layer::Full);
    m.fullStdError = stdError(Layer::Full);
    // All indirect light = bounce1 + bounce2 + bounce3plus.
    for (Layer l : {Layer::Bounce1, Layer::Bounce2, Layer::Bounce3Plus})
        addInto(m.fullIndirect, mean(l));

    if (bounces == kAllBounces || bounces >= 3) {
        // bounce3plus holds every bounce >= 3, so n >= 3 can only be matched by the full image.
        m.name = "full";
        m.final = m.full;
        m.finalStdError = m.fullStdError;
        m.indirect = m.fullIndirect;
        Image var;
        for (Layer l : {Layer::Bounce1, Layer::Bounce2, Layer::Bounce3Plus})
            addSquaredInto(var, stdError(l));
        sqrtInPlace(var);
        m.indirectStdError = std::move(var);
        return m;
    }
    std::vector<Layer> finalLayers{Layer::Emission, Layer::Direct};
    std::vector<Layer> indirectLayers;
    m.name = "emission+direct";
    const Layer kBounces[] = {Layer::Bounce1, Layer::Bounce2};
    for (int b = 0; b < bounces; ++b) {
        finalLayers.push_back(kBounces[b]);
        indirectLayers.push_back(kBounces[b]);
        m.name += '+';
        m.name += ref::layerName(kBounces[b]);
    }
    Image var;
    for (Layer l : finalLayers) {
        addInto(m.final, mean(l));
        addSquaredInto(var, stdError(l));
    }
    sqrtInPlace(var);
    m.finalStdError = std::move(var);
    if (!indirectLayers.empty()) {
        Image ivar;
        for (Layer l : indirectLayers) {
            addInto(m.indirect, mean(l));
            addSquaredInto(ivar, stdError(l));
        }
        sqrtInPlace(ivar);
        m.indirectStdError = std::move(ivar);
    }
    return m;
}

}  // namespace gilab::exp
