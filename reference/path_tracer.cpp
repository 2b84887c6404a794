// PathTracer: scene set-up, the tile/pixel/sample loop (TBB) and the settings description.
#include "reference/path_tracer.h"

#include <algorithm>
#include <atomic>
#include <bit>
#include <cmath>
#include <limits>
#include <sstream>

#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include "core/util/error.h"
#include "core/util/progress.h"
#include "reference/bsdf.h"
#include "reference/embree_scene.h"
#include "reference/integrator.h"
#include "reference/lights.h"
#include "reference/sampling.h"
#include "reference/texture_lookup.h"

namespace gilab::ref {
namespace {

/** Half-width of the centre filter, in pixels: 2^-10. A pixel centre lying exactly on an edge
 *  then sees both faces in proportion instead of one picked by rounding. */
constexpr float kCenterJitter = 0x1p-10f;

/** The camera ray's position inside the pixel. The sampler's dimensions are consumed either
 *  way, so both filters see the same random numbers along the rest of the path. */
glm::vec2 pixelOffset(Sampler& sampler, PixelFilter filter) {
    const glm::vec2 u = sampler.get2D();
    return filter == PixelFilter::Center ? 0.5f + (2.0f * u - 1.0f) * kCenterJitter : u;
}

/** uv at image point (px, py) on the plane of `tri` (the rasteriser interpolates attributes over
 *  the triangle's plane, also for helper pixels outside it); false if the ray misses the plane. */
bool planeUv(const PrimaryRays& rays, const MeshTriangle& tri, float px, float py, glm::vec2& uv) {
    const Ray ray = rays(px, py);
    const float denom = glm::dot(tri.n, ray.direction);
    if (!(std::abs(denom) > 1e-12f)) return false;
    const glm::vec3 q = ray.origin + ray.direction * (glm::dot(tri.n, tri.p0 - ray.origin) / denom);
    const glm::vec3 v = q - tri.p0;
    const glm::vec3 e1 = tri.e1(), e2 = tri.e2();
    const float d00 = glm::dot(e1, e1), d01 = glm::dot(e1, e2);
    const float d11 = glm::dot(e2, e2);
    const float d20 = glm::dot(v, e1), d21 = glm::dot(v, e2);
    const float det = d00 * d11 - d01 * d01;
    if (!(det > 0.0f)) return false;
    uv = tri.uvAt((d11 * d20 - d01 * d21) / det, (d00 * d21 - d01 * d20) / det);
    return std::isfinite(uv.x) && std::isfinite(uv.y);
}

/**
 * The rasteriser's texture footprint at pixel (x, y) on `tri`: its uv derivatives per 2 x 2 quad
 * (the pixel's quad's top-left pixel to its right and lower neighbours, as lavapipe's dFdx /
 * dFdy), from the uvs of the triangle's plane at those pixel centres. A plane seen edge-on gives
 * the coarsest level.
 */
TextureFootprint rasterFootprint(const PrimaryRays& rays, const MeshTriangle& tri, int x, int y) {
    const float qx = float(x & ~1) + 0.5f, qy = float(y & ~1) + 0.5f;
    glm::vec2 uv00, uv10, uv01;
    TextureFootprint fp;
    if (planeUv(rays, tri, qx, qy, uv00) && planeUv(rays, tri, qx + 1.0f, qy, uv10) &&
        planeUv(rays, tri, qx, qy + 1.0f, uv01)) {
        fp.dx = uv10 - uv00;
        fp.dy = uv01 - uv00;
    } else {
        fp.dx = fp.dy = glm::vec2(1e6f);
    }
    return fp;
}

/** Whether a triangle's material has any texture (the footprint matters only then). */
bool hasTextures(const Scene& scene, const MeshTriangle& tri) {
    const Material& m = scene.materials[tri.material];
    return m.baseColorTexture >= 0 || m.metallicRoughnessTexture >= 0 || m.emissiveTexture >= 0;
}

constexpr int kTileSize = 8;
constexpr int kPacketSize = 4;    // camera rays of a 4 x 4 pixel block share one rtcIntersect16
constexpr int kWaveSamples = 16;  // samples per pixel traced together as one wavefront
constexpr int kValuesPerPixel = kLayerCount * 3;

std::atomic<bool> g_rayPackets{true};

void validate(const Scene& scene, const ReferenceSettings& s) {
    if (s.maxBounces < 0) throw Error("reference: maxBounces must be >= 0");
    if (s.rouletteStartBounce < -1) throw Error("reference: rouletteStartBounce must be >= -1");
    if (!(s.rouletteThreshold > 0.0f && s.rouletteThreshold <= 1.0f))
        throw Error("reference: roulette_threshold must be in (0, 1]");
    if (s.batchSamples < 1) throw Error("reference: batchSamples must be >= 1");
    if (s.sobolReplicate < 1 || !std::has_single_bit(s.sobolReplicate))
        throw Error("reference: sobol_replicate must be a power of two (got " +
                    std::to_string(s.sobolReplicate) + ")");
    if (scene.settings.width < 1 || scene.settings.height < 1)
        throw Error("scene '" + scene.name + "': invalid resolution");
    const int texCount = int(scene.textures.size());
    for (const Material& m : scene.materials) {
        for (int t : {m.baseColorTexture, m.metallicRoughnessTexture, m.emissiveTexture}) {
            if (t >= texCount)
                throw Error("material '" + m.name + "' uses texture " + std::to_string(t) + " of " +
                            std::to_string(texCount));
        }
    }
}

}  // namespace

void setRayPackets(bool enabled) {
    g_rayPackets = enabled;
}

const char* samplerKindName(SamplerKind k) {
    return k == SamplerKind::Sobol ? "sobol" : "independent";
}

namespace {

/** The scene moved by -camera.position (RenderSpace::Camera; scene.h translateScene). */
Scene inRenderSpace(const Scene& s, RenderSpace space) {
    Scene out = s;
    if (space == RenderSpace::Camera) translateScene(out, -glm::dvec3(s.camera.position));
    return out;
}

}  // namespace

struct PathTracer::Impl {
    Impl(const Scene& s, const ReferenceSettings& st, RenderSpace space)
        : scene((validate(s, st), inRenderSpace(s, space))),
          settings(st),
          space(space),
          textures(scene.textures, st.pixelFilter == PixelFilter::Center),
          mesh(scene, textures),
          lights(scene, textures, mesh),
          integrator(scene, settings, mesh, lights, textures) {}

    /** Renders samples [first, first + count) of one tile into `out` (the accumulator's arrays
     *  sum, sumSq and, with replicates, replicateSumSq and replicateOpen; they hold the
     *  accumulator's values of those pixels on entry). */
    void renderTile(int tx, int ty, uint64_t first, uint32_t count, const Accumulator& acc,
                    std::vector<double>* const* out, PathCounters& counters, uint64_t& nonFinite,
                    bool packets);

    const Scene scene;  // a copy: the tracer never depends on the caller's lifetime
    const ReferenceSettings settings;
    const RenderSpace space;
    const TextureLookup textures;
    EmbreeScene mesh;  // non-const only for embree() (benchmarks)
    const LightSampler lights;
    const Integrator integrator;
    RayStats stats;
    std::vector<RecordedRay>* sink = nullptr;
    /** Per-thread wavefront buffers, reused across tiles and calls. */
    struct TileScratch {
        std::vector<PathState> paths;
        std::vector<int> pathPixel;  // tile pixel of each path
        std::vector<PathRadiance> radiance;
        WaveScratch wave;
    };
    tbb::enumerable_thread_specific<TileScratch> scratch;
    /** The next accumulator arrays (sum, sumSq, replicateSumSq, replicateOpen), swapped in
     *  when a call completes. */
    std::vector<double> scratch4[4];
};

void PathTracer::Impl::renderTile(int tx, int ty, uint64_t first, uint32_t count,
                                  const Accumulator& acc, std::vector<double>* const* out,
                                  PathCounters& counters, uint64_t& nonFinite, bool packets) {
    const int w = acc.width, h = acc.height;
    const int x0 = tx * kTileSize, y0 = ty * kTileSize;
    const int x1 = std::min(x0 + kTileSize, w), y1 = std::min(y0 + kTileSize, h);
    const int tw = x1 - x0;
    const int pixels = tw * (y1 - y0);

    // The tile's running sums, starting from the accumulator's (per pixel: layer, channel):
    // sum, sumSq and, with replicates, the finished replicates' squared sums and the open one's
    const uint32_t replicate = acc.replicate;
    const int arrays = replicate > 0 ? 4 : 2;
    const std::vector<double>* in[4] = {&acc.sum, &acc.sumSq, &acc.replicateSumSq,
                                        &acc.replicateOpen};
    using TileValues = double[kTileSize * kTileSize][kValuesPerPixel];
    TileValues tileSums[4];
    TileValues& sum = tileSums[0];
    TileValues& sumSq = tileSums[1];
    TileValues& repSq = tileSums[2];
    TileValues& repOpen = tileSums[3];
    for (int p = 0; p < pixels; ++p) {
        const int x = x0 + p % tw, y = y0 + p / tw;
        for (int l = 0; l < kLayerCount; ++l)
            for (int c = 0; c < 3; ++c) {
                const size_t i = acc.index(Layer(l), x, y, c);
                for (int a = 0; a < arrays; ++a)
                    tileSums[a][p][l * 3 + c] = (*in[a])[i];
            }
    }

    // Adds sample s of tile pixel p, in sample order; a sample with a NaN/Inf in any layer adds
    // nothing. The last sample of a replicate closes it: its sum's square is added.
    auto add = [&](int p, uint64_t s, const PathRadiance& r) {
        bool finite = true;
        for (int l = 0; l < kLayerCount; ++l)
            finite = finite && isFinite(r.L[l]);
        if (!finite) ++nonFinite;
        for (int v = 0; finite && v < kValuesPerPixel; ++v) {
            const double x = double(r.L[v / 3][v % 3]);
            sum[p][v] += x;
            sumSq[p][v] += x * x;
            if (replicate > 0) repOpen[p][v] += x;
        }
        if (replicate > 0 && ((s + 1) & (replicate - 1)) == 0)  // a power of two
            for (int v = 0; v < kValuesPerPixel; ++v) {
                repSq[p][v] += repOpen[p][v] * repOpen[p][v];
                repOpen[p][v] = 0.0;
            }
    };

    // Waves of kWaveSamples samples of every tile pixel; within a sample, 4 x 4 pixel blocks
    // (one camera-ray packet each). Each pixel still receives its samples in index order.
    const PrimaryRays cameraRay(scene.camera, w, h);
    TileScratch& ws = scratch.local();
    std::vector<PathState>& paths = ws.paths;
    std::vector<int>& pathPixel = ws.pathPixel;

    // Centre filter: the camera rays are traced here, a 4 x 4 block per packet, so each hit
    // gets the rasteriser's texture footprint before it is shaded
    const bool center = settings.pixelFilter == PixelFilter::Center;
    const uint32_t replicateLog2 = uint32_t(std::countr_zero(settings.sobolReplicate));
    auto traceCameraRays = [&]() {
        for (size_t first = 0; first < paths.size(); first += 16) {
            const int n = int(std::min<size_t>(16, paths.size() - first));
            glm::vec3 o[16], d[16];
            for (int i = 0; i < n; ++i) {
                o[i] = paths[first + size_t(i)].rayO;
                d[i] = paths[first + size_t(i)].rayD;
            }
            RayHit hits[16];
            if (packets) {
                mesh.intersect16(n, o, d, std::numeric_limits<float>::infinity(), hits);
            } else {
                for (int i = 0; i < n; ++i)
                    if (!mesh.intersect(o[i], d[i], 0.0f, std::numeric_limits<float>::infinity(),
                                        hits[i]))
                        hits[i].prim = ~0u;
            }
            for (int i = 0; i < n; ++i) {
                PathState& path = paths[first + size_t(i)];
                path.hit = hits[i];
                path.found = hits[i].prim != ~0u;
                // Only textured materials look anything up with the footprint (measured 3.6 % of
                // the time on the untextured Cornell box, docs/reference.md "Throughput")
                path.hasFootprint = path.found && hasTextures(scene, mesh.triangle(hits[i].prim));
                if (path.hasFootprint) {
                    const int tilePixel = pathPixel[first + size_t(i)];
                    path.footprint = rasterFootprint(cameraRay, mesh.triangle(hits[i].prim),
                                                     x0 + tilePixel % tw, y0 + tilePixel / tw);
                }
                if (sink)
                    sink->push_back(
                        {o[i], d[i], 0.0f, std::numeric_limits<float>::infinity(), false});
            }
            counters.cameraRays += uint64_t(n);
        }
    };
    for (uint64_t s0 = first; s0 < first + count; s0 += kWaveSamples) {
        const uint64_t s1 = std::min<uint64_t>(first + count, s0 + kWaveSamples);
        paths.clear();
        pathPixel.clear();
        for (uint64_t s = s0; s < s1; ++s)
            for (int by = y0; by < y1; by += kPacketSize)
                for (int bx = x0; bx < x1; bx += kPacketSize)
                    for (int y = by; y < std::min(by + kPacketSize, y1); ++y)
                        for (int x = bx; x < std::min(bx + kPacketSize, x1); ++x) {
                            const uint64_t pixelIndex = uint64_t(y) * uint64_t(w) + uint64_t(x);
                            PathState& path = paths.emplace_back();
                            path.sampler = Sampler(settings.seed, pixelIndex, s, settings.sampler,
                                                   replicateLog2);
                            const glm::vec2 u = pixelOffset(path.sampler, settings.pixelFilter);
                            const Ray ray = cameraRay(float(x) + u.x, float(y) + u.y);
                            path.rayO = ray.origin;
                            path.rayD = ray.direction;
                            path.slot = uint32_t(paths.size() - 1);
                            pathPixel.push_back((y - y0) * tw + (x - x0));
                        }
        if (center) traceCameraRays();
        ws.radiance.resize(paths.size());
        integrator.tracePaths(paths, ws.radiance.data(), center, packets, counters, sink, ws.wave);
        for (size_t i = 0; i < paths.size(); ++i)  // paths: sample-major, then tile pixels
            add(pathPixel[i], s0 + i / size_t(pixels), ws.radiance[i]);
    }

    for (int p = 0; p < pixels; ++p) {
        const int x = x0 + p % tw, y = y0 + p / tw;
        for (int l = 0; l < kLayerCount; ++l)
            for (int c = 0; c < 3; ++c) {
                const size_t i = acc.index(Layer(l), x, y, c);
                for (int a = 0; a < arrays; ++a)
                    (*out[a])[i] = tileSums[a][p][l * 3 + c];
            }
    }
}

PathTracer::PathTracer(const Scene& scene, const ReferenceSettings& settings, RenderSpace space)
    : m_impl(std::make_unique<Impl>(scene, settings, space)) {}

PathTracer::~PathTracer() = default;

bool PathTracer::addSamples(Accumulator& acc, uint32_t count, const std::atomic<bool>* cancel) {
    Impl& im = *m_impl;
    const int w = im.scene.settings.width, h = im.scene.settings.height;
    const size_t n = size_t(kLayerCount) * size_t(w) * size_t(h) * 3;
    if (acc.width != w || acc.height != h || acc.sum.size() != n || acc.sumSq.size() != n)
        throw Error("reference: the accumulator is " + std::to_string(acc.width) + "x" +
                    std::to_string(acc.height) + ", the scene " + std::to_string(w) + "x" +
                    std::to_string(h) + " (reset it first)");
    // Sobol samples come in independently scrambled replicates: a fresh accumulator keeps
    // their sums (the error bars); one made with other replicates cannot be continued
    const uint32_t replicate =
        im.settings.sampler == SamplerKind::Sobol ? im.settings.sobolReplicate : 0;
    if (acc.replicate != replicate) {
        if (acc.samples != 0)
            throw Error("reference: the accumulator's samples come in replicates of " +
                        std::to_string(acc.replicate) + ", these settings make " +
                        std::to_string(replicate) + " (0 = independent samples)");
        acc.reset(w, h, replicate);
    }
    if (count == 0) return true;
    const Stopwatch watch;

    // Render into scratch sums (initialised from acc per tile); commit only if not cancelled
    const int arrays = replicate > 0 ? 4 : 2;
    std::vector<double>* out[4];
    for (int a = 0; a < 4; ++a) {
        im.scratch4[a].resize(a < arrays ? n : 0);
        out[a] = &im.scratch4[a];
    }
    const int tilesX = (w + kTileSize - 1) / kTileSize, tilesY = (h + kTileSize - 1) / kTileSize;
    const int tileCount = tilesX * tilesY;
    const uint64_t first = acc.samples;
    const bool packets = g_rayPackets.load();
    std::atomic<bool> cancelled{false};
    std::atomic<uint64_t> cameraRays{0}, bounceRays{0}, shadowRays{0}, nonFinite{0};
    auto runTile = [&](int t) {
        if (cancelled.load(std::memory_order_relaxed)) return;
        if (cancel && cancel->load(std::memory_order_relaxed)) {
            cancelled = true;
            return;
        }
        PathCounters counters;
        uint64_t tileNonFinite = 0;
        im.renderTile(t % tilesX, t / tilesX, first, count, acc, out, counters, tileNonFinite,
                      packets);
        cameraRays += counters.cameraRays;
        bounceRays += counters.bounceRays;
        shadowRays += counters.shadowRays;
        nonFinite += tileNonFinite;
    };
    if (im.sink) {
        for (int t = 0; t < tileCount; ++t)  // recording: one thread, tile order
            runTile(t);
    } else {
        tbb::parallel_for(0, tileCount, runTile);
    }

    im.stats.cameraRays += cameraRays;
    im.stats.bounceRays += bounceRays;
    im.stats.shadowRays += shadowRays;
    im.stats.seconds += watch.elapsedMs() * 1e-3;
    im.mesh.checkError("tracing rays");
    if (cancelled) return false;
    acc.sum.swap(im.scratch4[0]);
    acc.sumSq.swap(im.scratch4[1]);
    acc.replicateSumSq.swap(im.scratch4[2]);
    acc.replicateOpen.swap(im.scratch4[3]);
    acc.samples += count;
    acc.nonFiniteSamples += nonFinite;
    im.stats.nonFiniteSamples += nonFinite;
    return true;
}

const RayStats& PathTracer::stats() const {
    return m_impl->stats;
}

const Scene& PathTracer::scene() const {
    return m_impl->scene;
}

const ReferenceSettings& PathTracer::settings() const {
    return m_impl->settings;
}

EmbreeScene& PathTracer::embree() {
    return m_impl->mesh;
}

void PathTracer::recordRays(std::vector<RecordedRay>* sink) {
    m_impl->sink = sink;
}

std::string PathTracer::toString() const {
    const Impl& im = *m_impl;
    const ReferenceSettings& s = im.settings;
    std::ostringstream out;
    out << "renderer: gilab reference path tracer v" << kRendererVersion << "\n"
        << "estimator: " << estimatorName(s.estimator)
        << (s.estimator == Estimator::Mis ? " (power heuristic, beta 2)" : "") << "\n"
        << "max_bounces: " << s.maxBounces << "\n"
        << "roulette_start_bounce: " << s.rouletteStartBounce
        << (s.rouletteStartBounce < 0 ? " (off)" : "") << "\n"
        << "roulette_threshold: " << s.rouletteThreshold
        << " (survival min(1, max(throughput) / threshold))\n"
        << "seed: " << s.seed << "\n"
        << "pixel filter: " << pixelFilterName(s.pixelFilter) << "\n"
        << "batch_samples: " << s.batchSamples << " (does not change the image)\n"
        << "ray_origins: exact hit point (double ray-plane), moved off the hit triangle and every "
           "neighbour within reach by 8x its Embree float-test error bound (reference/spawn.h)\n"
        << "render_space: "
        << (im.space == RenderSpace::Camera ? "camera (scene moved by -camera position)\n"
                                            : "world\n")
        << (s.sampler == SamplerKind::Independent
                ? "rng: independent uniform, SplitMix64 hash of (seed, pixel, sample, dimension)\n"
                : "rng: sobol, Owen-scrambled (0,2)-sequence per 1D/2D draw of the first 6, "
                  "shuffled index (Burley 2020), seeds from SplitMix64 of (seed, pixel, "
                  "replicate, draw); replicates of " +
                      std::to_string(s.sobolReplicate) +
                      " samples (error bars from their spread)\n")
        << "punctual_lights: " << im.lights.punctualCount() << ", all evaluated at every vertex\n"
        << "emissive_triangles: " << im.lights.emitterCount()
        << ", one sample per vertex by luminance power, uniform on the triangle\n"
        << "bsdf: glTF 2.0 Appendix B (Lambertian when metallic 0 and roughness 1), alpha >= "
        << kBrdfMinAlpha << "; sampling: cosine + GGX VNDF mixture\n"
        << "textures: mip 0, bilinear, sRGB decoded before filtering\n"
        << "non_finite: samples with NaN/Inf are counted and add 0\n"
        << "embree: " << im.mesh.version() << " (robust, high-quality BVH"
        << (im.mesh.hasAlphaFilter() ? ", alpha filter" : "") << ")\n";
    return out.str();
}

}  // namespace gilab::ref
