// Scene animation tests (Cpu* suites): frame times, keyframe interpolation (linear, slerp),
// frame states and their differences, the "animation" block of scene descriptions and its
// errors, and the animated variants of scenes/cornell_box.json and scenes/sponza.json.
#include <gtest/gtest.h>

#include "tests/temp_dir.h"

#include <atomic>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <unistd.h>

#include <glm/gtc/constants.hpp>

#include "core/scene/animation.h"
#include "core/scene/procedural_cornell.h"
#include "core/scene/scene.h"
#include "core/scene/scene_loader.h"
#include "core/util/error.h"

using namespace gilab;
namespace fs = std::filesystem;

namespace {

const std::string kShared = GILAB_SHARED_SCENES_DIR;
const std::string kScenes = std::string(GILAB_SOURCE_DIR) + "/scenes";

template <typename Fn>
void expectError(Fn&& fn, std::initializer_list<std::string> fragments) {
    try {
        fn();
        ADD_FAILURE() << "expected gilab::Error";
    } catch (const Error& e) {
        const std::string msg = e.what();
        for (const std::string& f : fragments)
            EXPECT_NE(msg.find(f), std::string::npos) << "'" << f << "' not in: " << msg;
    }
}

/** This file's temporary folders (tests/temp_dir.h). */
class TempDir : public test::TempDir {
public:
    TempDir() : test::TempDir("gilab_animation_test") {}
};

void expectVec(const glm::vec3& a, const glm::vec3& b, float tol = 1e-6f) {
    EXPECT_NEAR(a.x, b.x, tol);
    EXPECT_NEAR(a.y, b.y, tol);
    EXPECT_NEAR(a.z, b.z, tol);
}

bool finite(const glm::vec3& v) {
    return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

Light makeLight(const std::string& name, LightType type, glm::vec3 color, float strength) {
    Light l;
    l.name = name;
    l.type = type;
    l.color = color;
    l.strength = strength;
    l.intensity = color * strength;
    return l;
}

AnimationTrack track(AnimationProperty property, std::vector<AnimationKey> keys, uint32_t light = 0,
                     Interpolation mode = Interpolation::Linear) {
    AnimationTrack t;
    t.property = property;
    t.lightIndex = light;
    t.lightName = "l";
    t.lightName += std::to_string(light);
    t.interpolation = mode;
    t.keys = std::move(keys);
    return t;
}

/** Two lights (a spot and a sun) and the default camera; 5 frames over 2 s. */
Scene smallScene() {
    Scene s;
    s.lights.push_back(makeLight("l0", LightType::Spot, {1.0f, 0.5f, 0.25f}, 2.0f));
    s.lights.push_back(makeLight("l1", LightType::Directional, {1.0f, 1.0f, 1.0f}, 3.0f));
    s.animation.duration = 2.0;
    s.animation.frameCount = 5;
    return s;
}

const std::string kBox = R"("procedural": {"generator": "cornell_box", "light": false},
    "lights": [{"type": "spot", "name": "spot", "position": [0.278, 0.5, 0.28],
                "direction": [0, -1, 0], "intensity": 1},
               {"type": "point", "name": "bulb", "position": [0.2, 0.3, 0.2], "intensity": 1}])";

}  // namespace

// ---------------------------------------------------------------------------------------------
// Frame times and interpolation
// ---------------------------------------------------------------------------------------------

TEST(CpuAnimation, FrameTimes) {
    SceneAnimation a;
    EXPECT_FALSE(a.animated());
    EXPECT_EQ(a.frameTime(0), 0.0);
    a.duration = 4.0;
    a.frameCount = 9;
    EXPECT_EQ(a.frameTime(0), 0.0);
    EXPECT_DOUBLE_EQ(a.frameTime(1), 0.5);
    EXPECT_DOUBLE_EQ(a.frameTime(4), 2.0);
    EXPECT_EQ(a.frameTime(8), 4.0);
    EXPECT_EQ(a.frameTime(12), 4.0);  // clamped
    EXPECT_EQ(a.frameTime(-1), 0.0);
    a.frameCount = 3;
    a.duration = 1.0;
    EXPECT_EQ(a.frameTime(2), 1.0);  // the last frame is exactly the duration
    a.frameCount = 1;
    EXPECT_EQ(a.frameTime(0), 0.0);
    EXPECT_FALSE(a.animated());  // no tracks
}

TEST(CpuAnimation, LinearInterpolationAndClamping) {
    Scene s = smallScene();
    s.animation.tracks.push_back(track(AnimationProperty::LightPosition,
                                       {{1.0, {0, 0, 0}}, {2.0, {1, 2, 4}}, {3.0, {1, 2, 0}}}));
    expectVec(evaluateAnimation(s, 0.0).lights[0].position, {0, 0, 0});  // before the first key
    expectVec(evaluateAnimation(s, 1.0).lights[0].position, {0, 0, 0});
    expectVec(evaluateAnimation(s, 1.25).lights[0].position, {0.25f, 0.5f, 1.0f});
    expectVec(evaluateAnimation(s, 2.0).lights[0].position, {1, 2, 4});
    expectVec(evaluateAnimation(s, 2.5).lights[0].position, {1, 2, 2});
    expectVec(evaluateAnimation(s, 9.0).lights[0].position, {1, 2, 0});  // after the last key
    // The other light and the camera keep the scene's values
    const SceneFrameState st = evaluateAnimation(s, 1.5);
    EXPECT_EQ(st.lights[1].position, s.lights[1].position);
    EXPECT_EQ(st.camera.position, s.camera.position);

    // A single key holds everywhere
    Scene one = smallScene();
    one.animation.tracks.push_back(track(AnimationProperty::CameraFov, {{0.5, {30, 0, 0}}}));
    EXPECT_NEAR(evaluateAnimation(one, -3.0).camera.vfovRad, glm::radians(30.0f), 1e-7f);
    EXPECT_NEAR(evaluateAnimation(one, 3.0).camera.vfovRad, glm::radians(30.0f), 1e-7f);
}

TEST(CpuAnimation, SlerpOfDirections) {
    Scene s = smallScene();
    s.animation.tracks.push_back(track(AnimationProperty::LightDirection,
                                       {{0.0, {1, 0, 0}}, {2.0, {0, 1, 0}}}, 1,
                                       Interpolation::Slerp));
    // Perpendicular unit vectors: the bisector at t = 0.5, 30 degrees at 1/3
    expectVec(evaluateAnimation(s, 1.0).lights[1].direction, glm::normalize(glm::vec3(1, 1, 0)));
    const float a = glm::radians(30.0f);
    expectVec(evaluateAnimation(s, 2.0 / 3.0).lights[1].direction,
              {std::cos(a), std::sin(a), 0.0f});
    for (double t = 0.0; t <= 2.0; t += 0.125)
        EXPECT_NEAR(glm::length(evaluateAnimation(s, t).lights[1].direction), 1.0f, 1e-6f);

    // Linear interpolation of a direction is normalised (nlerp): same bisector at the middle
    s.animation.tracks[0].interpolation = Interpolation::Linear;
    expectVec(evaluateAnimation(s, 1.0).lights[1].direction, glm::normalize(glm::vec3(1, 1, 0)));
}

TEST(CpuAnimation, SlerpNearParallelAndOppositeHaveNoNaN) {
    const glm::vec3 up(0, 1, 0);
    const glm::vec3 nearUp = glm::normalize(glm::vec3(1e-7f, 1, 0));
    for (const glm::vec3& to : {up, nearUp, -up, -nearUp, glm::vec3(0, 0, 1)}) {
        Scene s = smallScene();
        s.animation.tracks.push_back(track(AnimationProperty::LightDirection,
                                           {{0.0, up}, {1.0, to}}, 0, Interpolation::Slerp));
        for (double t = 0.0; t <= 1.0; t += 0.05) {
            const glm::vec3 d = evaluateAnimation(s, t).lights[0].direction;
            ASSERT_TRUE(finite(d)) << "t " << t;
            EXPECT_NEAR(glm::length(d), 1.0f, 1e-5f);
        }
        expectVec(evaluateAnimation(s, 1.0).lights[0].direction, to);
    }
    // Opposite: half way is perpendicular to both
    Scene s = smallScene();
    s.animation.tracks.push_back(
        track(AnimationProperty::LightDirection, {{0.0, up}, {1.0, -up}}, 0, Interpolation::Slerp));
    EXPECT_NEAR(glm::dot(evaluateAnimation(s, 0.5).lights[0].direction, up), 0.0f, 1e-6f);
    // A linear direction track through zero (opposite keys, half way) takes the arc there
    s.animation.tracks[0].interpolation = Interpolation::Linear;
    const glm::vec3 mid = evaluateAnimation(s, 0.5).lights[0].direction;
    ASSERT_TRUE(finite(mid));
    EXPECT_NEAR(glm::length(mid), 1.0f, 1e-6f);
    expectVec(evaluateAnimation(s, 0.25).lights[0].direction, up);  // nlerp: still +y
}

TEST(CpuAnimation, IntensityAndColorKeepTheProduct) {
    Scene s = smallScene();
    s.animation.tracks.push_back(
        track(AnimationProperty::LightIntensity, {{0.0, {2, 0, 0}}, {2.0, {6, 0, 0}}}, 0));
    s.animation.tracks.push_back(
        track(AnimationProperty::LightColor, {{0.0, {1, 1, 1}}, {2.0, {0, 0.5f, 1}}}, 1));
    const SceneFrameState st = evaluateAnimation(s, 1.0);
    EXPECT_FLOAT_EQ(st.lights[0].strength, 4.0f);
    expectVec(st.lights[0].color, s.lights[0].color);
    expectVec(st.lights[0].intensity, s.lights[0].color * 4.0f);
    expectVec(st.lights[1].color, {0.5f, 0.75f, 1.0f});
    EXPECT_EQ(st.lights[1].strength, 3.0f);
    expectVec(st.lights[1].intensity, glm::vec3(0.5f, 0.75f, 1.0f) * 3.0f);
    for (const Light& l : st.lights)
        EXPECT_EQ(l.intensity, l.color * l.strength);
}

TEST(CpuAnimation, CameraTracks) {
    Scene s = smallScene();
    s.animation.tracks.push_back(
        track(AnimationProperty::CameraPosition, {{0.0, {0, 1, 4}}, {2.0, {0, 1, 2}}}));
    s.animation.tracks.push_back(
        track(AnimationProperty::CameraTarget, {{0.0, {0, 0, 0}}, {2.0, {0, 1, 0}}}));
    s.animation.tracks.push_back(
        track(AnimationProperty::CameraFov, {{0.0, {40, 0, 0}}, {2.0, {30, 0, 0}}}));
    const Camera c = frameState(s, 2).camera;  // t = 1
    expectVec(c.position, {0, 1, 3});
    expectVec(c.target, {0, 0.5f, 0});
    EXPECT_NEAR(c.vfovRad, glm::radians(35.0f), 1e-6f);
    EXPECT_EQ(c.up, s.camera.up);
    EXPECT_EQ(c.nearZ, s.camera.nearZ);
}

// ---------------------------------------------------------------------------------------------
// Frame states
// ---------------------------------------------------------------------------------------------

TEST(CpuAnimation, StaticSceneFrameStateIsTheScene) {
    Scene s = smallScene();
    s.animation = SceneAnimation{};
    const SceneFrameState st = frameState(s, 0);
    ASSERT_EQ(st.lights.size(), 2u);
    EXPECT_FALSE(diffFrameStates(st, frameState(s, 3)).any());
    EXPECT_EQ(st.lights[1].intensity, s.lights[1].intensity);
}

TEST(CpuAnimation, DiffReportsExactlyWhatChanged) {
    Scene s = smallScene();
    s.lights.push_back(makeLight("l2", LightType::Point, {1, 1, 1}, 1.0f));
    s.animation.tracks.push_back(
        track(AnimationProperty::LightPosition, {{0.0, {0, 0, 0}}, {1.0, {1, 0, 0}}}, 2));
    s.animation.tracks.push_back(
        track(AnimationProperty::CameraFov, {{1.0, {40, 0, 0}}, {2.0, {20, 0, 0}}}));

    // Frames 0 -> 1 (t 0 -> 0.5): light 2 only; the fov track has not started
    SceneChanges c = diffFrameStates(frameState(s, 0), frameState(s, 1));
    EXPECT_EQ(c.lights, std::vector<uint32_t>{2});
    EXPECT_FALSE(c.camera);
    EXPECT_FALSE(c.geometry);
    EXPECT_TRUE(c.any());
    // 2 -> 3 (t 1 -> 1.5): the light track has ended, the camera moves
    c = diffFrameStates(frameState(s, 2), frameState(s, 3));
    EXPECT_TRUE(c.lights.empty());
    EXPECT_TRUE(c.camera);
    // 0 -> 4: both
    c = diffFrameStates(frameState(s, 0), frameState(s, 4));
    EXPECT_EQ(c.lights, std::vector<uint32_t>{2});
    EXPECT_TRUE(c.camera);
    // Same frame: nothing
    EXPECT_FALSE(diffFrameStates(frameState(s, 3), frameState(s, 3)).any());

    // Every light field counts, exactly
    SceneFrameState a = frameState(s, 0), b = a;
    b.lights[0].strength = std::nextafter(b.lights[0].strength, 10.0f);
    b.lights[1].outerConeRad += 0.01f;
    EXPECT_EQ(diffFrameStates(a, b).lights, (std::vector<uint32_t>{0, 1}));
    b = a;
    b.lights[1].range = 5.0f;
    b.camera.farZ = 7.0f;
    c = diffFrameStates(a, b);
    EXPECT_EQ(c.lights, std::vector<uint32_t>{1});
    EXPECT_TRUE(c.camera);
    b = a;
    b.lights[0].color.y += 0.5f;
    EXPECT_EQ(diffFrameStates(a, b).lights, std::vector<uint32_t>{0});
}

TEST(CpuAnimation, ApplyFrameState) {
    Scene s = makeCornellBox(CornellBoxParams{});
    s.lights.push_back(makeLight("p", LightType::Point, {1, 1, 1}, 1.0f));
    s.animation.duration = 1.0;
    s.animation.frameCount = 3;
    s.animation.tracks.push_back(
        track(AnimationProperty::LightPosition, {{0.0, {0, 0, 0}}, {1.0, {0.2f, 0.4f, 0}}}));
    s.animation.tracks.push_back(
        track(AnimationProperty::CameraPosition,
              {{0.0, s.camera.position}, {1.0, s.camera.position + glm::vec3(0, 0, 0.5f)}}));
    const size_t triangles = s.triangleCount();
    const std::vector<Vertex> vertices = s.vertices;
    const SceneFrameState st = frameState(s, 1);
    applyFrameState(s, st);
    expectVec(s.lights[0].position, {0.1f, 0.2f, 0});
    EXPECT_EQ(s.camera.position, st.camera.position);
    EXPECT_EQ(s.triangleCount(), triangles);
    EXPECT_EQ(s.vertices.size(), vertices.size());
    // Applying is idempotent: the tracks own what they animate
    EXPECT_FALSE(diffFrameStates(frameState(s, 1), st).any());
    applyFrameState(s, frameState(s, 2));
    applyFrameState(s, frameState(s, 0));
    expectVec(s.lights[0].position, {0, 0, 0});

    SceneFrameState wrong = st;
    wrong.lights.pop_back();
    expectError([&] { applyFrameState(s, wrong); }, {"lights"});
}

// ---------------------------------------------------------------------------------------------
// Scene descriptions
// ---------------------------------------------------------------------------------------------

TEST(CpuAnimationFile, ParsesTheBlockAndResolvesLights) {
    TempDir dir;
    const std::string path = dir.write("anim.json", "{" + kBox + R"(,
        "extra_lights": [{"type": "directional", "name": "sun", "direction": [0, -1, 0],
                          "color": [1, 0.5, 0.5], "intensity": 2}],
        "animation": {"duration_s": 2, "frames": 3, "tracks": [
            {"target": "light:sun.direction", "keys": [[0, [-1, -1, 0]], [2, [1, -1, 0]]]},
            {"target": "light:sun.intensity", "keys": [[0, 2], [2, 4]]},
            {"target": "light:sun.color", "keys": [[0, [1, 0.5, 0.5]], [2, [1, 1, 1]]]},
            {"target": "light:bulb.position", "keys": [[0, [0.2, 0.3, 0.2]], [1, [0.3, 0.3, 0.2]]]},
            {"target": "camera.target", "keys": [[0, [0.278, 0.273, 0.2]], [2, [0.3, 0.2, 0.2]]]},
            {"target": "camera.vfov_deg", "keys": [[0, 40], [2, 30]]}]},
        "variants": {"short": {"animation": {"duration_s": 1, "frames": 2, "tracks": [
            {"target": "light:spot.intensity", "keys": [[0, 1], [1, 0]]}]}},
                     "still": {"animation": null}}})");
    const Scene s = loadSceneFile(path);
    ASSERT_EQ(s.lights.size(), 3u);
    EXPECT_EQ(s.lights[2].color, glm::vec3(1, 0.5f, 0.5f));
    EXPECT_EQ(s.lights[2].strength, 2.0f);
    EXPECT_EQ(s.lights[2].intensity, glm::vec3(2, 1, 1));
    EXPECT_NEAR(s.camera.vfovRad, glm::radians(40.0f), 1e-6f);  // loaded at frame 0, not 39.3
    const SceneAnimation& a = s.animation;
    ASSERT_TRUE(a.animated());
    EXPECT_EQ(a.frameCount, 3);
    EXPECT_EQ(a.duration, 2.0);
    ASSERT_EQ(a.tracks.size(), 6u);
    EXPECT_EQ(a.tracks[0].lightIndex, 2u);                       // sun: after the two "lights"
    EXPECT_EQ(a.tracks[0].interpolation, Interpolation::Slerp);  // the default for directions
    expectVec(a.tracks[0].keys[0].value, glm::normalize(glm::vec3(-1, -1, 0)));  // normalised
    EXPECT_EQ(a.tracks[1].interpolation, Interpolation::Linear);
    EXPECT_EQ(a.tracks[3].lightIndex, 1u);  // bulb
    EXPECT_EQ(animationTarget(a.tracks[3]), "light:bulb.position");
    EXPECT_EQ(animationTarget(a.tracks[5]), "camera.vfov_deg");

    const SceneFrameState mid = frameState(s, 1);
    expectVec(mid.lights[2].direction, {0, -1, 0});
    expectVec(mid.lights[2].intensity, glm::vec3(1, 0.75f, 0.75f) * 3.0f);
    expectVec(mid.lights[1].position, {0.3f, 0.3f, 0.2f});
    EXPECT_NEAR(mid.camera.vfovRad, glm::radians(35.0f), 1e-6f);

    // A variant's block replaces the base's as a whole; null removes it
    const Scene v = loadSceneFile(path, "short");
    EXPECT_EQ(v.animation.frameCount, 2);
    ASSERT_EQ(v.animation.tracks.size(), 1u);
    EXPECT_EQ(v.animation.tracks[0].lightIndex, 0u);
    EXPECT_FALSE(loadSceneFile(path, "still").animation.animated());
}

TEST(CpuAnimationFile, BadBlocksNameTheKey) {
    TempDir dir;
    auto check = [&](const std::string& name, const std::string& animation,
                     std::initializer_list<std::string> fragments) {
        const std::string path =
            dir.write(name, "{" + kBox + ", \"animation\": " + animation + "}");
        SCOPED_TRACE(name);
        expectError([&] { loadSceneFile(path); }, fragments);
    };
    const std::string head = R"({"duration_s": 4, "frames": 9, "tracks": [)";
    check("unknown_light.json",
          head + R"({"target": "light:lamp.position", "keys": [[0, [0,0,0]]]}]})",
          {"unknown_light.json", "animation.tracks[0].target", "unknown light \"lamp\"",
           "spot, bulb"});
    check("node.json", head + R"({"target": "node:door.translation", "keys": [[0, [0,0,0]]]}]})",
          {"node.json", "animation.tracks[0].target", "rigid node transforms are not supported"});
    check("decreasing.json",
          head + R"({"target": "light:spot.intensity", "keys": [[0, 1], [2, 2], [1, 3]]}]})",
          {"decreasing.json", "animation.tracks[0].keys[2][0]", "increase strictly"});
    check("equal.json", head + R"({"target": "light:spot.intensity", "keys": [[1, 1], [1, 2]]}]})",
          {"equal.json", "animation.tracks[0].keys[1][0]", "increase strictly"});
    check("slerp_position.json",
          head + R"({"target": "light:spot.position", "interpolation": "slerp",
                     "keys": [[0, [0,0,0]]]}]})",
          {"slerp_position.json", "animation.tracks[0].interpolation", "direction tracks only"});
    check("interp.json", head + R"({"target": "light:spot.direction", "interpolation": "cubic",
                     "keys": [[0, [0,-1,0]]]}]})",
          {"interp.json", "animation.tracks[0].interpolation", "linear, slerp"});
    check("frames.json", R"({"duration_s": 4, "frames": 0, "tracks": []})",
          {"frames.json", "animation.frames", "out of range"});
    check("manyframes.json", R"({"duration_s": 4, "frames": 10001, "tracks": []})",
          {"manyframes.json", "animation.frames"});
    check("duration.json",
          R"({"duration_s": 0, "frames": 9, "tracks": [
              {"target": "light:spot.intensity", "keys": [[0, 1]]}]})",
          {"duration.json", "animation.duration_s", "must be > 0"});
    check("notracks.json", R"({"duration_s": 1, "frames": 2, "tracks": []})",
          {"notracks.json", "animation.tracks", "at least one track"});
    check("nokeys.json", head + R"({"target": "light:spot.intensity", "keys": []}]})",
          {"nokeys.json", "animation.tracks[0].keys", "at least one key"});
    check("zerodir.json", head + R"({"target": "light:spot.direction", "keys": [[0, [0,0,0]]]}]})",
          {"zerodir.json", "animation.tracks[0].keys[0][1]", "zero-length"});
    check("negintensity.json", head + R"({"target": "light:spot.intensity", "keys": [[0, -1]]}]})",
          {"negintensity.json", "animation.tracks[0].keys[0][1]", "out of range"});
    check("negcolor.json", head + R"({"target": "light:spot.color", "keys": [[0, [1,-1,1]]]}]})",
          {"negcolor.json", "animation.tracks[0].keys[0][1][1]", "out of range"});
    check("fov.json", head + R"({"target": "camera.vfov_deg", "keys": [[0, 180]]}]})",
          {"fov.json", "animation.tracks[0].keys[0][1]", "(0, 180)"});
    check("scalar.json", head + R"({"target": "light:spot.intensity", "keys": [[0, [1,1,1]]]}]})",
          {"scalar.json", "animation.tracks[0].keys[0][1]", "expected a number"});
    check("vector.json", head + R"({"target": "light:spot.position", "keys": [[0, 1]]}]})",
          {"vector.json", "animation.tracks[0].keys[0][1]", "expected an array"});
    check("pair.json", head + R"({"target": "light:spot.intensity", "keys": [[0, 1, 2]]}]})",
          {"pair.json", "animation.tracks[0].keys[0]", "[time, value]"});
    check("duplicate.json", head + R"({"target": "light:spot.intensity", "keys": [[0, 1]]},
                    {"target": "light:spot.intensity", "keys": [[0, 2]]}]})",
          {"duplicate.json", "animation.tracks[1].target", "second track", "animation.tracks[0]"});
    check("property.json", head + R"({"target": "light:spot.colour", "keys": [[0, [1,1,1]]]}]})",
          {"property.json", "animation.tracks[0].target", "unknown light property \"colour\""});
    check("camprop.json", head + R"({"target": "camera.up", "keys": [[0, [0,1,0]]]}]})",
          {"camprop.json", "animation.tracks[0].target", "unknown camera property \"up\""});
    check("target.json", head + R"({"target": "sun.direction", "keys": [[0, [0,1,0]]]}]})",
          {"target.json", "animation.tracks[0].target", "unknown target"});
    check("pointdir.json",
          head + R"({"target": "light:bulb.direction", "keys": [[0, [0,-1,0]]]}]})",
          {"pointdir.json", "animation.tracks[0].target", "point light"});
    check("key.json", R"({"duration_s": 1, "frames": 2, "loop": true, "tracks": []})",
          {"key.json", "unknown key \"animation.loop\""});
    check("trackkey.json", head + R"({"target": "light:spot.intensity", "key": [[0, 1]]}]})",
          {"trackkey.json", "unknown key \"animation.tracks[0].key\""});
    check("camera_meets_target.json", head + R"({"target": "camera.position",
                     "keys": [[0, [0.278, 0.273, -0.8]], [4, [0.278, 0.273, 1.2]]]}]})",
          {"camera_meets_target.json", "frame 4", "camera position equals target"});
}

TEST(CpuAnimationFile, VariantErrorsNameTheVariant) {
    TempDir dir;
    const std::string path = dir.write("v.json", "{" + kBox + R"(, "variants": {"moving":
        {"animation": {"duration_s": 1, "frames": 2, "tracks": [
            {"target": "light:lamp.intensity", "keys": [[0, 1]]}]}}}})");
    EXPECT_FALSE(loadSceneFile(path).animation.animated());  // the base has no animation
    expectError([&] { loadSceneFile(path, "moving"); },
                {"v.json", "variant \"moving\"", "unknown light \"lamp\"", "spot, bulb"});
}

// ---------------------------------------------------------------------------------------------
// The animated variants of the shipped scene files
// ---------------------------------------------------------------------------------------------

TEST(CpuAnimationScenes, CornellSpotOrbit) {
    const Scene s = loadSceneFile(kScenes + "/cornell_box.json", "spot_orbit");
    const Scene spot = loadSceneFile(kScenes + "/cornell_box.json", "spot");
    ASSERT_EQ(s.animation.frameCount, 9);
    EXPECT_EQ(s.animation.duration, 4.0);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].name, spot.lights[0].name);
    EXPECT_EQ(s.lights[0].intensity, spot.lights[0].intensity);
    EXPECT_EQ(s.lights[0].outerConeRad, spot.lights[0].outerConeRad);
    EXPECT_EQ(s.caps.triangleCount, spot.caps.triangleCount);

    const SceneFrameState first = frameState(s, 0), last = frameState(s, 8);
    EXPECT_FALSE(diffFrameStates(first, last).any()) << "the orbit ends where it starts";
    EXPECT_EQ(first.lights[0].position, s.lights[0].position) << "loaded at frame 0";
    float lo = 1.0f, hi = 0.0f;
    for (int f = 0; f < 9; ++f) {
        const SceneFrameState st = frameState(s, f);
        const glm::vec3 p = st.lights[0].position;
        EXPECT_GT(p.x, 0.05f);
        EXPECT_LT(p.x, kCornellRoomSize.x - 0.05f);
        EXPECT_GT(p.y, 0.5f);
        EXPECT_LT(p.y, kCornellRoomSize.y);
        EXPECT_GT(p.z, 0.0f);
        EXPECT_LT(p.z, kCornellRoomSize.z);
        lo = std::min(lo, p.x);
        hi = std::max(hi, p.x);
        if (f > 0) {
            const SceneChanges c = diffFrameStates(frameState(s, f - 1), st);
            EXPECT_EQ(c.lights, std::vector<uint32_t>{0});
            EXPECT_FALSE(c.camera);
        }
    }
    EXPECT_GT(hi - lo, 0.3f) << "sweeps across the ceiling";
}

TEST(CpuAnimationScenes, CornellCameraDolly) {
    const Scene s = loadSceneFile(kScenes + "/cornell_box.json", "camera_dolly");
    ASSERT_EQ(s.animation.frameCount, 9);
    EXPECT_TRUE(s.caps.hasEmissive);  // the built-in area light
    EXPECT_TRUE(s.lights.empty());
    const SceneFrameState first = frameState(s, 0), mid = frameState(s, 4);
    EXPECT_EQ(first.camera.position, s.camera.position);
    EXPECT_GT(mid.camera.position.z, first.camera.position.z + 0.2f);  // dollied in
    EXPECT_LT(mid.camera.position.z, 0.0f);                            // still outside the box
    EXPECT_FALSE(diffFrameStates(first, frameState(s, 8)).any());
    const SceneChanges c = diffFrameStates(first, frameState(s, 1));
    EXPECT_TRUE(c.camera);
    EXPECT_TRUE(c.lights.empty());
}

TEST(CpuAnimationScenes, SponzaSunArc) {
    if (!fs::exists(kShared + "/dabrovic-sponza/sponza.gltf"))
        GTEST_SKIP() << "shared scenes not found at " << kShared;
    const Scene s = loadSceneFile(kScenes + "/sponza.json", "sun_arc");
    ASSERT_EQ(s.animation.frameCount, 9);
    ASSERT_EQ(s.lights.size(), 1u);
    EXPECT_EQ(s.lights[0].name, "sun");
    const glm::vec3 d0 = frameState(s, 0).lights[0].direction;
    EXPECT_EQ(d0, s.lights[0].direction);  // loading applies frame 0
    const glm::vec3 d8 = frameState(s, 8).lights[0].direction;
    // Across the atrium (which runs along x): the direction's z changes sign, light stays downward
    EXPECT_LT(d0.z, -0.1f);
    EXPECT_GT(d8.z, 0.1f);
    for (int f = 0; f < 9; ++f) {
        const glm::vec3 d = frameState(s, f).lights[0].direction;
        EXPECT_NEAR(glm::length(d), 1.0f, 1e-6f);
        EXPECT_LT(d.y, -0.9f);
    }
    EXPECT_EQ(diffFrameStates(frameState(s, 3), frameState(s, 4)).lights, std::vector<uint32_t>{0});
}
