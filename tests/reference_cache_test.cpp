// The reference cache: key stability, atomic store/load, corruption, continuation and
// `gilab reference` end to end (docs/reference_cache.md). Tiny images, few samples.
#include <unistd.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <optional>
#include <set>
#include <string_view>
#include <thread>

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>
#include "tests/temp_dir.h"

#include "core/image/image_io.h"
#include "core/scene/scene_loader.h"
#include "core/util/error.h"
#include "core/util/file_lock.h"
#include "experiments/cli/cli.h"
#include "experiments/cli/interrupt.h"
#include "reference/bench.h"
#include "reference/cache.h"
#include "reference/reference_settings.h"
#include "reference/scene_hash.h"

namespace gilab {
namespace {
namespace fs = std::filesystem;

Scene tinyScene() {
    Scene scene = makeBuiltinDefaultScene();
    scene.settings.width = 12;
    scene.settings.height = 10;
    return scene;
}

ref::ReferenceSettings tinySettings() {
    ref::ReferenceSettings s;
    s.maxBounces = 2;
    s.batchSamples = 4;
    return s;
}

ref::StopCriteria samplesStop(uint64_t n) {
    return ref::StopCriteria{n, 0.0, 0.0};
}

/** This file's temporary folders (tests/temp_dir.h). */
class TempDir : public test::TempDir {
public:
    TempDir() : test::TempDir("gilab_refcache") {}
};

/** A synthetic accumulator with irregular values (no rendering). */
ref::Accumulator syntheticAccumulator(int w, int h, uint64_t samples, uint32_t replicate = 0) {
    ref::Accumulator acc;
    acc.reset(w, h, replicate);
    acc.samples = samples;
    acc.nonFiniteSamples = 3;
    for (size_t i = 0; i < acc.sum.size(); ++i) {
        acc.sum[i] = double(i) * 0.1234567 + 1.0 / double(i + 3);
        acc.sumSq[i] = acc.sum[i] * acc.sum[i] * 1.5 + 1e-9 * double(i);
        if (replicate > 0) {
            acc.replicateSumSq[i] = acc.sumSq[i] * 0.75 + 1e-7 * double(i);
            acc.replicateOpen[i] = 0.5 / double(i + 1);
        }
    }
    return acc;
}

nlohmann::ordered_json minimalSidecar(const std::string& key, const ref::Accumulator& acc,
                                      const char* status = "complete") {
    return {{"status", status}, {"key", key}, {"samples", acc.samples}};
}

bool bitEqual(const ref::Accumulator& a, const ref::Accumulator& b) {
    return a.width == b.width && a.height == b.height && a.samples == b.samples &&
           a.nonFiniteSamples == b.nonFiniteSamples && a.sum.size() == b.sum.size() &&
           a.sumSq.size() == b.sumSq.size() &&
           std::memcmp(a.sum.data(), b.sum.data(), a.sum.size() * sizeof(double)) == 0 &&
           std::memcmp(a.sumSq.data(), b.sumSq.data(), a.sumSq.size() * sizeof(double)) == 0 &&
           a.replicate == b.replicate && a.replicateSumSq == b.replicateSumSq &&
           a.replicateOpen == b.replicateOpen;
}

std::string errorOf(const std::function<void()>& f) {
    try {
        f();
    } catch (const Error& e) {
        return e.what();
    }
    return "";
}

nlohmann::json readJson(const fs::path& path) {
    std::ifstream in(path);
    return nlohmann::json::parse(in);
}

const std::string kKey = std::string(32, 'a');

/**
 * One edit per field of ReferenceSettings, by its name in ref::settingsJson(), moving the field
 * away from its value (a valid setting still: the Sobol replicate stays a power of two). The
 * test below requires these names to be exactly the keys of the serialisation, so a field added
 * to settingsJson() needs an edit here and one dropped from it fails; a field added to the
 * struct but not to settingsJson() stops the build there (its structured binding).
 */
const std::map<std::string, std::function<void(ref::ReferenceSettings&)>>& settingEdits() {
    static const std::map<std::string, std::function<void(ref::ReferenceSettings&)>> edits = {
        {"max_bounces", [](ref::ReferenceSettings& r) { r.maxBounces += 1; }},
        {"roulette_start_bounce", [](ref::ReferenceSettings& r) { r.rouletteStartBounce += 1; }},
        {"roulette_threshold", [](ref::ReferenceSettings& r) { r.rouletteThreshold *= 0.5f; }},
        {"estimator",
         [](ref::ReferenceSettings& r) {
             r.estimator =
                 r.estimator == ref::Estimator::Mis ? ref::Estimator::NeeOnly : ref::Estimator::Mis;
         }},
        {"seed", [](ref::ReferenceSettings& r) { r.seed += 1; }},
        {"pixel_filter",
         [](ref::ReferenceSettings& r) {
             r.pixelFilter = r.pixelFilter == ref::PixelFilter::Box ? ref::PixelFilter::Center
                                                                    : ref::PixelFilter::Box;
         }},
        {"sampler",
         [](ref::ReferenceSettings& r) {
             r.sampler = r.sampler == ref::SamplerKind::Sobol ? ref::SamplerKind::Independent
                                                              : ref::SamplerKind::Sobol;
         }},
        {"sobol_replicate", [](ref::ReferenceSettings& r) { r.sobolReplicate /= 2; }},
        {"batch_samples", [](ref::ReferenceSettings& r) { r.batchSamples *= 2; }},
    };
    return edits;
}

template <size_t N>
bool listed(const std::array<std::string_view, N>& list, const std::string& name) {
    return std::find(list.begin(), list.end(), name) != list.end();
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// Key

TEST(CpuReferenceKey, SameInputGivesSameKey) {
    const std::string a = ref::referenceKey(tinyScene(), tinySettings());
    const std::string b = ref::referenceKey(tinyScene(), tinySettings());
    EXPECT_EQ(a, b);
    EXPECT_EQ(a.size(), 32u);
    EXPECT_EQ(a.find_first_not_of("0123456789abcdef"), std::string::npos);
}

TEST(CpuReferenceKey, EveryImageInputChangesTheKey) {
    using Edit = std::function<void(Scene&, ref::ReferenceSettings&)>;
    const std::vector<std::pair<const char*, Edit>> edits = {
        {"light intensity", [](Scene& s, auto&) { s.lights.push_back(Light{}); }},
        {"material colour", [](Scene& s, auto&) { s.materials[0].baseColorFactor.r *= 0.5f; }},
        {"emission", [](Scene& s, auto&) { s.materials.back().emissiveFactor.g += 1.0f; }},
        {"camera position", [](Scene& s, auto&) { s.camera.position.x += 1e-3f; }},
        {"camera fov", [](Scene& s, auto&) { s.camera.vfovRad *= 1.01f; }},
        {"resolution", [](Scene& s, auto&) { s.settings.width += 1; }},
        {"vertex", [](Scene& s, auto&) { s.vertices[0].position.y += 1e-4f; }},
        {"triangle material", [](Scene& s, auto&) { s.triangleMaterials[0] ^= 1u; }},
        {"max bounces", [](Scene&, auto& r) { r.maxBounces += 1; }},
        {"roulette", [](Scene&, auto& r) { r.rouletteStartBounce = 3; }},
        {"estimator", [](Scene&, auto& r) { r.estimator = ref::Estimator::NeeOnly; }},
        {"seed", [](Scene&, auto& r) { r.seed += 1; }},
        {"pixel filter", [](Scene&, auto& r) { r.pixelFilter = ref::PixelFilter::Box; }},
        {"sampler",
         [](Scene&, auto& r) {
             r.sampler = r.sampler == ref::SamplerKind::Sobol ? ref::SamplerKind::Independent
                                                              : ref::SamplerKind::Sobol;
         }},
        {"sobol replicate",
         [](Scene&, auto& r) {
             r.sampler = ref::SamplerKind::Sobol;
             r.sobolReplicate = 16;
         }},
    };
    std::set<std::string> keys = {ref::referenceKey(tinyScene(), tinySettings())};
    for (const auto& [what, edit] : edits) {
        Scene scene = tinyScene();
        ref::ReferenceSettings settings = tinySettings();
        edit(scene, settings);
        EXPECT_TRUE(keys.insert(ref::referenceKey(scene, settings)).second) << what;
    }
    // A light's intensity alone
    Scene withLight = tinyScene();
    withLight.lights.push_back(Light{});
    const std::string before = ref::referenceKey(withLight, tinySettings());
    withLight.lights.back().intensity.b = 2.0f;
    EXPECT_NE(ref::referenceKey(withLight, tinySettings()), before);
}

TEST(CpuReferenceKey, BatchSamplesNamesAndExposureKeepTheKey) {
    const std::string base = ref::referenceKey(tinyScene(), tinySettings());
    ref::ReferenceSettings settings = tinySettings();
    settings.batchSamples = 16;
    EXPECT_EQ(ref::referenceKey(tinyScene(), settings), base);
    Scene scene = tinyScene();
    scene.name = "renamed";
    scene.materials[0].name = "renamed";
    scene.settings.exposureEv = 2.0f;
    EXPECT_EQ(ref::referenceKey(scene, tinySettings()), base);
}

TEST(CpuReferenceKey, EverySettingChangesTheKeyUnlessExcludedByName) {
    const Scene scene = tinyScene();
    const ref::ReferenceSettings defaults;
    const nlohmann::ordered_json serialised = ref::settingsJson(defaults);
    ref::ReferenceSettings sobol = defaults;
    sobol.sampler = ref::SamplerKind::Sobol;

    // The exclusions name real fields (a typo would exclude nothing)
    for (std::string_view name : ref::kSettingsNotInKey)
        EXPECT_TRUE(serialised.contains(std::string(name))) << name;
    for (std::string_view name : ref::kSobolOnlySettings)
        EXPECT_TRUE(serialised.contains(std::string(name))) << name;

    // Every serialised field has an edit, and every edit's field is serialised
    std::set<std::string> names;
    for (const auto& item : serialised.items()) {
        names.insert(item.key());
        EXPECT_TRUE(settingEdits().count(item.key())) << "no edit for the field " << item.key();
    }
    for (const auto& [name, edit] : settingEdits())
        EXPECT_TRUE(names.count(name)) << name << " is not in ref::settingsJson()";

    // Each edit changes its own field of the serialisation, and the key unless excluded; from
    // the defaults, and from the Sobol sampler, which reads the Sobol-only fields
    for (const auto& [name, edit] : settingEdits()) {
        for (const ref::ReferenceSettings& base : {defaults, sobol}) {
            const bool isSobol = base.sampler == ref::SamplerKind::Sobol;
            ref::ReferenceSettings changed = base;
            edit(changed);
            const nlohmann::ordered_json before = ref::settingsJson(base);
            nlohmann::ordered_json after = ref::settingsJson(changed);
            if (before.contains(name)) {  // (else reported above; the key is still checked)
                EXPECT_NE(after[name], before[name]) << name << " (sobol " << isSobol << ")";
                after[name] = before[name];
                EXPECT_EQ(after, before) << "the edit of " << name << " changes other fields";
            }

            const bool excluded = listed(ref::kSettingsNotInKey, name) ||
                                  (!isSobol && listed(ref::kSobolOnlySettings, name));
            const bool keyChanged =
                ref::referenceKey(scene, changed) != ref::referenceKey(scene, base);
            EXPECT_EQ(keyChanged, !excluded)
                << name
                << (excluded ? " is excluded from the key but changes it"
                             : " changes the image but not the key")
                << " (sobol " << isSobol << ")";
        }
    }
}

TEST(CpuReferenceKey, SidecarHoldsEverySetting) {
    ref::ReferenceSettings settings = tinySettings();
    for (const auto& [name, edit] : settingEdits())
        edit(settings);  // every field away from tinySettings()
    const ref::ReferenceResult r =
        ref::obtainReference(tinyScene(), settings, samplesStop(1), nullptr);
    ASSERT_TRUE(r.sidecar.contains("settings"));
    const nlohmann::ordered_json& stored = r.sidecar["settings"];
    EXPECT_EQ(stored, ref::settingsJson(settings));
    const nlohmann::ordered_json plain = ref::settingsJson(tinySettings());
    for (const auto& [name, edit] : settingEdits()) {
        ASSERT_TRUE(stored.contains(name)) << name;
        EXPECT_NE(stored[name], plain[name]) << name;
    }
    // The key's description lists the settings it hashed: all but the excluded ones (and the
    // Sobol-only ones when the edits left the sampler independent)
    const bool sobol = settings.sampler == ref::SamplerKind::Sobol;
    for (const auto& item : stored.items())
        EXPECT_EQ(r.sidecar["key_description"]["settings"].contains(item.key()),
                  !listed(ref::kSettingsNotInKey, item.key()) &&
                      (sobol || !listed(ref::kSobolOnlySettings, item.key())))
            << item.key();
}

TEST(CpuReferenceKey, LoadedFileBytesChangeTheKey) {
    TempDir tmp;
    const fs::path file = tmp.path() / "mesh.bin";
    std::ofstream(file, std::ios::binary) << "0123456789";
    Scene scene = tinyScene();
    scene.loadedFiles.push_back(file.string());
    const ref::ReferenceKey a = ref::computeReferenceKey(scene, tinySettings());
    EXPECT_EQ(ref::referenceKey(scene, tinySettings()), a.hex);
    std::ofstream(file, std::ios::binary) << "0123456780";  // same size, one byte differs
    EXPECT_NE(ref::referenceKey(scene, tinySettings()), a.hex);
    ASSERT_EQ(a.description["files"].size(), 1u);
    EXPECT_EQ(a.description["files"][0]["bytes"], 10);
    EXPECT_EQ(a.description["settings"]["max_bounces"], 2);

    fs::remove(file);
    const std::string message = errorOf([&] { ref::referenceKey(scene, tinySettings()); });
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
}

TEST(CpuReferenceKey, SceneFilesAndVariantsHaveTheirOwnKeys) {
    const std::string path = std::string(GILAB_SOURCE_DIR) + "/scenes/cornell_box.json";
    const Scene base = loadSceneFile(path);
    const Scene spot = loadSceneFile(path, "spot");
    const ref::ReferenceKey a = ref::computeReferenceKey(base, tinySettings());
    EXPECT_NE(a.hex, ref::referenceKey(spot, tinySettings()));
    EXPECT_EQ(a.description["files"].size(), base.loadedFiles.size());
    // The built-in box is the same image as cornell_box.json; only the file bytes differ
    EXPECT_EQ(ref::hashSceneData(base), ref::hashSceneData(makeBuiltinDefaultScene()));
}

// ---------------------------------------------------------------------------------------------
// Store and load

TEST(CpuReferenceCache, AccumulatorRoundTripIsBitExact) {
    TempDir tmp;
    const ref::Accumulator acc = syntheticAccumulator(5, 3, 17);
    ref::writeAccumulatorFile(tmp.path() / "a.bin", acc);
    EXPECT_TRUE(bitEqual(ref::readAccumulatorFile(tmp.path() / "a.bin"), acc));

    const ref::ReferenceCache cache(tmp.path() / "cache");
    EXPECT_FALSE(cache.load(kKey).has_value());
    cache.store(kKey, acc, minimalSidecar(kKey, acc));
    const auto loaded = cache.load(kKey);
    ASSERT_TRUE(loaded.has_value());
    EXPECT_TRUE(bitEqual(loaded->acc, acc));
    EXPECT_TRUE(loaded->complete);
    EXPECT_EQ(loaded->dir, cache.entryDir(kKey));
    const std::vector<ImageLayer> layers = readExrLayers((loaded->dir / "reference.exr").string());
    ASSERT_EQ(layers.size(), size_t(2 * ref::kLayerCount));
    EXPECT_EQ(layers[0].name, "full");
    EXPECT_EQ(layers[ref::kLayerCount].name, "full_stderr");
}

TEST(CpuReferenceCache, SobolReplicateSumsRoundTripAndIndependentFilesKeepFormat1) {
    TempDir tmp;
    const ref::Accumulator sobol = syntheticAccumulator(4, 3, 96, 16);
    ref::writeAccumulatorFile(tmp.path() / "s.bin", sobol);
    const ref::Accumulator back = ref::readAccumulatorFile(tmp.path() / "s.bin");
    EXPECT_TRUE(bitEqual(back, sobol));
    EXPECT_EQ(back.replicate, 16u);
    EXPECT_DOUBLE_EQ(back.stdError(ref::Layer::Direct, 1, 2, 1),
                     sobol.stdError(ref::Layer::Direct, 1, 2, 1));
    // Format 1 (no replicates) is unchanged: 48-byte header, two arrays, checksum
    const ref::Accumulator iid = syntheticAccumulator(4, 3, 96);
    ref::writeAccumulatorFile(tmp.path() / "i.bin", iid);
    EXPECT_EQ(std::filesystem::file_size(tmp.path() / "i.bin"),
              48u + 2u * iid.sum.size() * sizeof(double) + 16u);
    EXPECT_EQ(std::filesystem::file_size(tmp.path() / "s.bin"),
              56u + 4u * iid.sum.size() * sizeof(double) + 16u);
    // A replicate size that is not a power of two is named as corrupt
    std::fstream f(tmp.path() / "s.bin", std::ios::in | std::ios::out | std::ios::binary);
    const uint64_t bad = 12;
    f.seekp(48);
    f.write(reinterpret_cast<const char*>(&bad), sizeof bad);
    f.close();
    const std::string e = errorOf([&] { ref::readAccumulatorFile(tmp.path() / "s.bin"); });
    EXPECT_NE(e.find("s.bin"), std::string::npos) << e;
    EXPECT_NE(e.find("replicate"), std::string::npos) << e;
}

TEST(CpuReferenceCache, StoreReplacesAnEntryAndLeavesNoTemporaries) {
    TempDir tmp;
    const ref::ReferenceCache cache(tmp.path());
    cache.store(kKey, syntheticAccumulator(4, 4, 4),
                minimalSidecar(kKey, syntheticAccumulator(4, 4, 4), "partial"));
    EXPECT_FALSE(cache.load(kKey)->complete);
    const ref::Accumulator eight = syntheticAccumulator(4, 4, 8);
    cache.store(kKey, eight, minimalSidecar(kKey, eight));
    EXPECT_TRUE(bitEqual(cache.load(kKey)->acc, eight));
    for (const auto& e : fs::directory_iterator(tmp.path()))
        EXPECT_EQ(e.path().filename().string(), kKey);
}

TEST(CpuReferenceCache, CorruptAccumulatorIsDetectedNamingTheFile) {
    TempDir tmp;
    const ref::ReferenceCache cache(tmp.path());
    const ref::Accumulator acc = syntheticAccumulator(6, 5, 9);
    const fs::path file = cache.entryDir(kKey) / "accumulator.bin";
    auto freshEntry = [&] { cache.store(kKey, acc, minimalSidecar(kKey, acc)); };
    auto flipByte = [&](std::streamoff offset) {
        std::fstream f(file, std::ios::in | std::ios::out | std::ios::binary);
        f.seekg(offset);
        char c = 0;
        f.get(c);
        f.seekp(offset);
        f.put(char(c ^ 0x10));
    };
    const std::streamoff size = std::streamoff(fs::file_size((freshEntry(), file)));
    for (std::streamoff offset :
         {std::streamoff(0), std::streamoff(20), std::streamoff(100), size - 20, size - 1}) {
        freshEntry();
        flipByte(offset);
        const std::string message = errorOf([&] { cache.load(kKey); });
        EXPECT_NE(message.find(file.string()), std::string::npos) << offset << ": " << message;
    }
    freshEntry();
    fs::resize_file(file, fs::file_size(file) - 8);
    std::string message = errorOf([&] { cache.load(kKey); });
    EXPECT_NE(message.find(file.string()), std::string::npos) << message;
    EXPECT_NE(message.find("truncated"), std::string::npos) << message;

    // A sidecar that disagrees with the accumulator is corrupt too
    freshEntry();
    nlohmann::ordered_json sidecar = minimalSidecar(kKey, acc);
    sidecar["samples"] = 10;
    std::ofstream(cache.entryDir(kKey) / "reference.json") << sidecar.dump();
    message = errorOf([&] { cache.load(kKey); });
    EXPECT_NE(message.find("reference.json"), std::string::npos) << message;
    EXPECT_NE(errorOf([&] { cache.entryDir("../escape"); }), "");
}

TEST(CpuReferenceCache, TemporaryFoldersAreNeverLoadedAndStaleOnesAreCleaned) {
    TempDir tmp;
    const ref::ReferenceCache source(tmp.path() / "source");
    const ref::Accumulator acc = syntheticAccumulator(3, 3, 4);
    source.store(kKey, acc, minimalSidecar(kKey, acc));
    // A crash after writing everything but before the rename: a complete-looking .tmp folder
    const ref::ReferenceCache cache(tmp.path() / "cache");
    fs::create_directories(cache.dir());
    const fs::path stale = cache.dir() / (".tmp-" + kKey + "-999999-0");
    const fs::path recent = cache.dir() / (".tmp-" + kKey + "-999998-0");
    fs::copy(source.entryDir(kKey), stale);
    fs::copy(source.entryDir(kKey), recent);
    EXPECT_FALSE(cache.load(kKey).has_value());

    fs::last_write_time(stale, fs::file_time_type::clock::now() - std::chrono::hours(25));
    const std::string other = std::string(32, 'b');
    cache.store(other, acc, minimalSidecar(other, acc));
    EXPECT_FALSE(fs::exists(stale));
    EXPECT_TRUE(fs::exists(recent));  // may belong to a running process
    EXPECT_FALSE(cache.load(kKey).has_value());
}

// ---------------------------------------------------------------------------------------------
// obtainReference

TEST(CpuObtainReference, SecondIdenticalRequestRendersNothing) {
    TempDir tmp;
    const ref::ReferenceCache cache(tmp.path());
    const ref::ReferenceResult first =
        ref::obtainReference(tinyScene(), tinySettings(), samplesStop(8), &cache);
    EXPECT_FALSE(first.cacheHit);
    EXPECT_EQ(first.renderedSamples, 8u);
    EXPECT_EQ(first.sidecar["status"], "complete");
    EXPECT_EQ(first.sidecar["samples"], 8);

    const ref::ReferenceResult second =
        ref::obtainReference(tinyScene(), tinySettings(), samplesStop(8), &cache);
    EXPECT_TRUE(second.cacheHit);
    EXPECT_EQ(second.renderedSamples, 0u);
    EXPECT_EQ(second.report.rays.totalRays(), 0u);
    EXPECT_TRUE(bitEqual(second.acc, first.acc));

    // Fewer samples, a time budget, or a looser error target are met by the stored entry
    EXPECT_TRUE(ref::obtainReference(tinyScene(), tinySettings(), samplesStop(4), &cache).cacheHit);
    EXPECT_TRUE(
        ref::obtainReference(tinyScene(), tinySettings(), ref::StopCriteria{0, 0.0, 5.0}, &cache)
            .cacheHit);
    EXPECT_TRUE(
        ref::obtainReference(tinyScene(), tinySettings(), ref::StopCriteria{0, 1e6, 0.0}, &cache)
            .cacheHit);
    EXPECT_THROW(ref::obtainReference(tinyScene(), tinySettings(), ref::StopCriteria{}, &cache),
                 Error);
}

TEST(CpuObtainReference, ConcurrentRequestsRenderOnceAndShareTheEntry) {
    // Three obtainers of one key at once (flock conflicts between separate opens, so threads
    // stand in for processes): one renders, the others wait for its lock and reuse the entry
    TempDir tmp;
    const ref::ReferenceCache cache(tmp.path());
    std::vector<ref::ReferenceResult> results(3);
    std::vector<std::thread> threads;
    for (size_t i = 0; i < results.size(); ++i)
        threads.emplace_back([&, i] {
            results[i] = ref::obtainReference(tinyScene(), tinySettings(), samplesStop(16), &cache);
        });
    for (std::thread& t : threads)
        t.join();
    int rendered = 0;
    for (const ref::ReferenceResult& r : results) {
        EXPECT_TRUE(r.complete);
        EXPECT_EQ(r.acc.samples, 16u);
        EXPECT_TRUE(bitEqual(r.acc, results[0].acc));
        rendered += r.renderedSamples > 0 ? 1 : 0;
        EXPECT_EQ(r.cacheHit, r.renderedSamples == 0);
    }
    EXPECT_EQ(rendered, 1);
    EXPECT_TRUE(std::filesystem::exists(cache.lockPath(results[0].key)));
}

TEST(CpuObtainReference, TheLockHolderRemovesADeadProcesssTemporariesOfItsKeyOnly) {
    TempDir tmp;
    const ref::ReferenceCache cache(tmp.path());
    const std::string key = ref::referenceKey(tinyScene(), tinySettings());
    const fs::path dead = tmp.path() / (".tmp-" + key + "-node7-4242-0");
    const fs::path otherKey = tmp.path() / (".tmp-" + std::string(32, 'c') + "-node7-4242-0");
    fs::create_directories(dead);
    fs::create_directories(otherKey);
    ref::obtainReference(tinyScene(), tinySettings(), samplesStop(4), &cache);
    EXPECT_FALSE(fs::exists(dead));     // recent, but its key's lock was free: its writer is dead
    EXPECT_TRUE(fs::exists(otherKey));  // another key: maybe a live writer
}

TEST(CpuObtainReference, WaitingForAnotherRendererCanBeCancelled) {
    TempDir tmp;
    const ref::ReferenceCache cache(tmp.path());
    const std::string key = ref::referenceKey(tinyScene(), tinySettings());
    std::optional<FileLock> held = FileLock::tryAcquire(cache.lockPath(key));
    ASSERT_TRUE(held);
    std::atomic<bool> cancel{false};
    std::thread canceller([&] {
        std::this_thread::sleep_for(std::chrono::milliseconds(300));
        cancel = true;
    });
    ref::ObtainOptions options;
    options.cancel = &cancel;
    const ref::ReferenceResult r =
        ref::obtainReference(tinyScene(), tinySettings(), samplesStop(8), &cache, options);
    canceller.join();
    EXPECT_EQ(r.reason, ref::StopReason::Cancelled);
    EXPECT_FALSE(r.complete);
    EXPECT_EQ(r.renderedSamples, 0u);
    EXPECT_FALSE(std::filesystem::exists(cache.entryDir(key)));
}

TEST(CpuObtainReference, MoreSamplesContinueAndEqualAFreshRender) {
    TempDir tmp;
    const ref::ReferenceCache cache(tmp.path());
    ref::obtainReference(tinyScene(), tinySettings(), samplesStop(8), &cache);
    ref::ReferenceSettings finer = tinySettings();
    finer.batchSamples = 2;  // same key: batching does not change the image
    const ref::ReferenceResult more =
        ref::obtainReference(tinyScene(), finer, samplesStop(20), &cache);
    EXPECT_FALSE(more.cacheHit);
    EXPECT_EQ(more.continuedFromSamples, 8u);
    EXPECT_EQ(more.renderedSamples, 12u);
    EXPECT_EQ(more.acc.samples, 20u);
    EXPECT_EQ(more.sidecar["history"].size(), 2u);

    const ref::ReferenceResult fresh =
        ref::obtainReference(tinyScene(), tinySettings(), samplesStop(20), nullptr);
    EXPECT_EQ(fresh.continuedFromSamples, 0u);
    EXPECT_TRUE(bitEqual(more.acc, fresh.acc));
    EXPECT_TRUE(bitEqual(cache.load(more.key)->acc, fresh.acc));
}

TEST(CpuObtainReference, CancelledRenderIsStoredPartialAndContinued) {
    TempDir tmp;
    const ref::ReferenceCache cache(tmp.path());
    ref::ReferenceResult partial;
    for (int attempt = 0; attempt < 5 && partial.acc.samples == 0; ++attempt) {
        std::atomic<bool> cancel{false};
        std::thread canceller([&] {
            std::this_thread::sleep_for(std::chrono::milliseconds(50 << attempt));
            cancel = true;
        });
        partial = ref::obtainReference(tinyScene(), tinySettings(), samplesStop(1u << 30), &cache,
                                       ref::ObtainOptions{&cancel});
        canceller.join();
        EXPECT_EQ(partial.reason, ref::StopReason::Cancelled);
    }
    const uint64_t n = partial.acc.samples;
    ASSERT_GT(n, 0u);
    EXPECT_EQ(n % 4, 0u);  // a batch boundary
    EXPECT_FALSE(partial.complete);
    const auto stored = cache.load(partial.key);
    ASSERT_TRUE(stored.has_value());
    EXPECT_FALSE(stored->complete);
    EXPECT_EQ(stored->sidecar["stop_reason"], "cancelled");
    EXPECT_EQ(stored->acc.samples, n);

    // A partial entry never meets a time budget: it is continued
    const ref::ReferenceResult timed = ref::obtainReference(
        tinyScene(), tinySettings(), ref::StopCriteria{n + 8, 0.0, 30.0}, &cache);
    EXPECT_FALSE(timed.cacheHit);
    EXPECT_EQ(timed.continuedFromSamples, n);
    EXPECT_EQ(timed.acc.samples, n + 8);
    EXPECT_TRUE(cache.load(timed.key)->complete);
    const ref::ReferenceResult fresh =
        ref::obtainReference(tinyScene(), tinySettings(), samplesStop(n + 8), nullptr);
    EXPECT_TRUE(bitEqual(timed.acc, fresh.acc));
}

TEST(CpuObtainReference, CorruptEntryIsRenderedAgainWithAWarning) {
    TempDir tmp;
    const ref::ReferenceCache cache(tmp.path());
    const ref::ReferenceResult first =
        ref::obtainReference(tinyScene(), tinySettings(), samplesStop(4), &cache);
    fs::resize_file(cache.entryDir(first.key) / "accumulator.bin", 100);
    const ref::ReferenceResult again =
        ref::obtainReference(tinyScene(), tinySettings(), samplesStop(4), &cache);
    EXPECT_FALSE(again.cacheHit);
    ASSERT_EQ(again.warnings.size(), 1u);
    EXPECT_NE(again.warnings[0].find("accumulator.bin"), std::string::npos);
    EXPECT_TRUE(bitEqual(again.acc, first.acc));
    EXPECT_TRUE(bitEqual(cache.load(first.key)->acc, first.acc));
}

// ---------------------------------------------------------------------------------------------
// `gilab reference`

TEST(CpuReferenceCommand, WritesOutputsAndReusesTheCache) {
    TempDir tmp;
    cli::ReferenceOptions o;
    o.spp = 8;
    o.maxBounces = 2;
    o.resolution = "12x10";
    o.cacheDir = (tmp.path() / "cache").string();
    o.outDir = (tmp.path() / "out").string();
    o.quiet = true;
    o.commandLine = "gilab reference --spp 8";
    ASSERT_EQ(cli::runReference(o), cli::kExitOk);
    const fs::path out = tmp.path() / "out";
    for (const char* f : {"reference.exr", "reference.png", "reference.json"})
        EXPECT_TRUE(fs::exists(out / f)) << f;
    nlohmann::json j = readJson(out / "reference.json");
    EXPECT_EQ(j["status"], "complete");
    EXPECT_EQ(j["samples"], 8);
    EXPECT_EQ(j["stop_reason"], "samples");
    EXPECT_EQ(j["cache"]["hit"], false);
    EXPECT_EQ(j["cache"]["continued_from_samples"], 0);
    const std::string key = j["cache"]["key"];
    EXPECT_EQ(key, j["key"]);
    EXPECT_TRUE(fs::exists(tmp.path() / "cache" / key / "accumulator.bin"));
    EXPECT_EQ(j["provenance"]["command_line"], "gilab reference --spp 8");
    EXPECT_EQ(j["scene"]["resolution"][0], 12);
    EXPECT_EQ(j["settings"]["max_bounces"], 2);
    // The rasteriser's footprint by default, recorded in the EXRs' headers (issue 27)
    EXPECT_EQ(j["settings"]["pixel_filter"], "center");
    EXPECT_EQ(readImageStringAttribute((out / "reference.exr").string(), kPixelFilterAttribute),
              "center");
    EXPECT_EQ(readImageStringAttribute((tmp.path() / "cache" / key / "reference.exr").string(),
                                       kPixelFilterAttribute),
              "center");
    EXPECT_EQ(j["key_description"]["key"], key);
    EXPECT_TRUE(j["renderer"]["tracer"].is_string());
    EXPECT_TRUE(j["rel_error"].is_number());
    EXPECT_EQ(j["nonfinite_samples"], 0);
    const auto layers = readExrLayers((out / "reference.exr").string());
    // The plain R,G,B channels (the main image, `full`) + mean and stderr layers.
    ASSERT_EQ(layers.size(), size_t(2 * ref::kLayerCount + 1));
    EXPECT_EQ(layers[0].name, "");
    EXPECT_EQ(layers[0].image.width(), 12);
    ASSERT_NE(findLayer(layers, "full"), nullptr);
    EXPECT_EQ(layers[0].image.values(), findLayer(layers, "full")->values());

    ASSERT_EQ(cli::runReference(o), cli::kExitOk);
    j = readJson(out / "reference.json");
    EXPECT_EQ(j["cache"]["hit"], true);
    EXPECT_EQ(j["cache"]["rendered_samples"], 0);

    o.spp = 12;
    ASSERT_EQ(cli::runReference(o), cli::kExitOk);
    j = readJson(out / "reference.json");
    EXPECT_EQ(j["cache"]["hit"], false);
    EXPECT_EQ(j["cache"]["continued_from_samples"], 8);
    EXPECT_EQ(j["samples"], 12);
}

TEST(CpuReferenceCommand, LongReferenceAddsTheConvergenceCurve) {
    TempDir tmp;
    cli::ReferenceOptions o;
    o.spp = 16;
    o.maxBounces = 1;
    o.resolution = "8x8";
    o.noCache = true;
    o.seed = 7;
    o.outDir = (tmp.path() / "long").string();
    o.quiet = true;
    ASSERT_EQ(cli::runReference(o), cli::kExitOk);
    o.spp = 8;
    o.seed = 1;
    o.batchSamples = 4;
    o.outDir = (tmp.path() / "short").string();
    o.longReference = (tmp.path() / "long" / "reference.exr").string();
    ASSERT_EQ(cli::runReference(o), cli::kExitOk);
    const nlohmann::json j = readJson(tmp.path() / "short" / "reference.json");
    EXPECT_EQ(j["cache"]["enabled"], false);
    ASSERT_EQ(j["convergence"]["curve"].size(), 2u);  // one point per batch of 4
    EXPECT_EQ(j["convergence"]["curve"][1]["samples"], 8);
    EXPECT_GT(j["convergence"]["curve"][1]["rel_mse_vs_long"].get<double>(), 0.0);
    std::ifstream csv(tmp.path() / "short" / "convergence.csv");
    std::string line;
    int lines = 0;
    while (std::getline(csv, line))
        ++lines;
    EXPECT_EQ(lines, 3);
}

TEST(CpuReferenceCommand, CancelWritesAPartialResultAndExits130) {
    TempDir tmp;
    std::atomic<bool> cancel{true};  // as if Ctrl-C came before the first batch finished
    cli::ReferenceOptions o;
    o.spp = 8;
    o.maxBounces = 1;
    o.resolution = "8x8";
    o.cacheDir = (tmp.path() / "cache").string();
    o.outDir = (tmp.path() / "out").string();
    o.quiet = true;
    o.cancel = &cancel;
    EXPECT_EQ(cli::runReference(o), cli::kExitInterrupted);
    const nlohmann::json j = readJson(tmp.path() / "out" / "reference.json");
    EXPECT_EQ(j["status"], "partial");
    EXPECT_EQ(j["stop_reason"], "cancelled");
    EXPECT_EQ(cli::kExitInterrupted, 130);
}

// ---------------------------------------------------------------------------------------------
// `gilab bench reference` (figures only; here: that every part runs and agrees with itself)

TEST(CpuReferenceBench, ReplayAndConvergenceRunOnATinyScene) {
    Scene scene = tinyScene();
    scene.settings.width = scene.settings.height = 8;
    ref::BenchOptions o;
    o.spp = 8;
    o.minReplaySeconds = 0.0;
    o.longSpp = 64;
    o.targetRelMse = 0.5;
    const ref::BenchSceneResult r = ref::benchReferenceScene(scene, tinySettings(), o);
    EXPECT_EQ(r.spp, 8u);
    EXPECT_EQ(r.rays.cameraRays, 8u * 64u);
    EXPECT_GT(r.replay.closestRays, 0u);
    EXPECT_GT(r.replay.shadowRays, 0u);
    ASSERT_FALSE(r.replay.closest.empty());
    for (const auto* set : {&r.replay.closest, &r.replay.shadow})
        for (const ref::ReplayRate& rate : *set)
            EXPECT_GT(rate.raysPerSecond(), 0.0) << rate.method;
    EXPECT_TRUE(r.replay.warnings.empty()) << r.replay.warnings.front();
    EXPECT_GT(r.replay.closest.front().hitsPerPass, 0u);
    EXPECT_LE(r.replay.closest.front().hitsPerPass, r.replay.closestRays);
    EXPECT_GT(r.rawMixRaysPerSecond("1", r.threads), 0.0);
    EXPECT_EQ(r.convergence.longSamples, 64u);
    // The prediction comes from the long run's variance, the sizing from the timed render's
    EXPECT_GT(r.convergence.predictedSamples, 0u);
    EXPECT_GT(r.convergence.sizingSamples, 0u);
    EXPECT_EQ(ref::benchSceneJson(r)["convergence"]["sizing_samples"], r.convergence.sizingSamples);
    EXPECT_TRUE(r.convergence.reached);
    EXPECT_LT(r.convergence.curve.back().relMseVsLong, 0.5);
    EXPECT_TRUE(ref::benchSceneJson(r)["raw_embree"]["closest"].is_array());
    // Efficiency 1 / (relMSE x seconds) from the extrapolation; the best raw mode is at least
    // as fast as single rays, so the path tracer's ratio to it is at most its ratio to those
    const nlohmann::ordered_json j = ref::benchSceneJson(r);
    const ref::BenchConvergence& c = r.convergence;
    ASSERT_GT(c.extrapolatedSeconds, 0.0);
    EXPECT_DOUBLE_EQ(c.efficiency(), 1.0 / (o.targetRelMse * c.extrapolatedSeconds));
    EXPECT_DOUBLE_EQ(c.secondsPerSample(), c.curve.back().seconds / double(c.curve.back().samples));
    EXPECT_DOUBLE_EQ(j["convergence"]["efficiency"].get<double>(), c.efficiency());
    const double overBest = j["raw_embree"]["path_tracer_over_best_raw_mt"].get<double>();
    EXPECT_GT(overBest, 0.0);
    EXPECT_LE(overBest, j["raw_embree"]["path_tracer_over_raw_1_mt"].get<double>());
}

}  // namespace gilab
