// renderUntil: batches of samples until a stop criterion holds, with a progress line.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "core/util/error.h"
#include "core/util/progress.h"
#include "reference/path_tracer.h"

namespace gilab::ref {
namespace {

RayStats difference(const RayStats& after, const RayStats& before) {
    RayStats d;
    d.cameraRays = after.cameraRays - before.cameraRays;
    d.bounceRays = after.bounceRays - before.bounceRays;
    d.shadowRays = after.shadowRays - before.shadowRays;
    d.seconds = after.seconds - before.seconds;
    d.nonFiniteSamples = after.nonFiniteSamples - before.nonFiniteSamples;
    return d;
}

}  // namespace

const char* stopReasonName(StopReason r) {
    switch (r) {
        case StopReason::Samples:
            return "samples";
        case StopReason::RelError:
            return "rel_error";
        case StopReason::Time:
            return "time";
        case StopReason::Cancelled:
            return "cancelled";
    }
    return "?";
}

RenderReport renderUntil(PathTracer& tracer, Accumulator& acc, const StopCriteria& stop,
                         const std::atomic<bool>* cancel, const Image* longReference) {
    if (stop.maxSamples == 0 && !(stop.targetRelError > 0.0) && !(stop.maxSeconds > 0.0))
        throw Error("reference: no stop criterion (set samples, relative error or time)");
    if (longReference && (longReference->width() != acc.width ||
                          longReference->height() != acc.height || longReference->channels() != 3))
        throw Error("reference: the long reference is " + std::to_string(longReference->width()) +
                    "x" + std::to_string(longReference->height()) + "x" +
                    std::to_string(longReference->channels()) + ", expected " +
                    std::to_string(acc.width) + "x" + std::to_string(acc.height) + " RGB");

    RenderReport report;
    const RayStats before = tracer.stats();
    const uint64_t startSamples = acc.samples;
    const Stopwatch watch;
    const double cpuStart = processCpuSeconds();
    Progress progress("reference " + tracer.scene().name);
    report.relError = meanRelativeStdError(acc, Layer::Full);

    auto met = [&](double seconds, StopReason& reason) {
        if (stop.maxSamples > 0 && acc.samples >= stop.maxSamples) {
            reason = StopReason::Samples;
        } else if (stop.targetRelError > 0.0 && report.relError <= stop.targetRelError) {
            reason = StopReason::RelError;
        } else if (stop.maxSeconds > 0.0 && seconds >= stop.maxSeconds) {
            reason = StopReason::Time;
        } else {
            return false;
        }
        return true;
    };

    StopReason reason = StopReason::Samples;
    while (!met(watch.elapsedMs() * 1e-3, reason)) {
        if (cancel && cancel->load()) {
            reason = StopReason::Cancelled;
            break;
        }
        uint32_t count = tracer.settings().batchSamples;
        if (stop.maxSamples > 0)
            count = uint32_t(std::min<uint64_t>(count, stop.maxSamples - acc.samples));
        if (!tracer.addSamples(acc, count, cancel)) {
            reason = StopReason::Cancelled;
            break;
        }
        const double seconds = watch.elapsedMs() * 1e-3;
        report.relError = meanRelativeStdError(acc, Layer::Full);
        const double relMse = longReference
                                  ? relativeMse(meanImage(acc, Layer::Full), *longReference)
                                  : std::numeric_limits<double>::quiet_NaN();
        report.curve.push_back({acc.samples, seconds, report.relError, relMse});

        // Progress: rate of this call and the nearest criterion's ETA (error ~ 1/sqrt(n))
        const double rate = double(acc.samples - startSamples) / std::max(seconds, 1e-9);
        double eta = std::numeric_limits<double>::infinity();
        if (stop.maxSamples > 0) eta = std::min(eta, double(stop.maxSamples - acc.samples) / rate);
        if (stop.maxSeconds > 0.0) eta = std::min(eta, stop.maxSeconds - seconds);
        if (stop.targetRelError > 0.0 && std::isfinite(report.relError)) {
            const double needed =
                double(acc.samples) * std::pow(report.relError / stop.targetRelError, 2.0);
            eta = std::min(eta, std::max(0.0, needed - double(acc.samples)) / rate);
        }
        const RayStats now = difference(tracer.stats(), before);
        char detail[192];
        std::snprintf(detail, sizeof detail,
                      "%llu spp, %.2f spp/s, %.2f Mrays/s, rel err %.4g, eta %.0fs",
                      static_cast<unsigned long long>(acc.samples), rate,
                      double(now.totalRays()) / std::max(now.seconds, 1e-9) * 1e-6, report.relError,
                      std::max(0.0, eta));
        progress.update(size_t(acc.samples), detail);
    }

    report.reason = reason;
    report.samples = acc.samples;
    report.seconds = watch.elapsedMs() * 1e-3;
    report.cpuSeconds = processCpuSeconds() - cpuStart;
    report.rays = difference(tracer.stats(), before);
    char detail[160];
    std::snprintf(detail, sizeof detail, "%llu spp, rel err %.4g, stopped: %s",
                  static_cast<unsigned long long>(acc.samples), report.relError,
                  stopReasonName(reason));
    progress.finish(detail);
    return report;
}

}  // namespace gilab::ref
