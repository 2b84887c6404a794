#pragma once
/**
 * glTF accessor decoding: every component type (normalized integers mapped per the spec),
 * byte strides, accessors without a buffer view (zeros) and sparse accessors. Every index,
 * size and offset is checked (in 64-bit arithmetic, overflow included) against the bufferViews
 * and buffers *before* anything of the declared size is allocated; errors name `what` (file,
 * mesh, attribute) and the accessor.
 */
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

namespace gilab::gltf {

/** Which component types an accessor may use (glTF 2.0, section 3.7.2.1). */
enum class ComponentRule {
    Any,                        // any type; integers normalized if the accessor says so
    Float,                      // FLOAT only (POSITION, NORMAL)
    FloatOrNormalizedUnsigned,  // FLOAT, or normalized UNSIGNED_BYTE / UNSIGNED_SHORT (TEXCOORD)
};

/**
 * An accessor without a bufferView is all zeros (plus its sparse values); nothing in the file
 * bounds its count, so it may have at most this many elements.
 */
constexpr size_t kMaxUnbackedElements = size_t(1) << 24;

/**
 * Reads accessor `index` as `components` floats per element (SCALAR = 1 ... VEC4 = 4); the
 * accessor's type must match and its component type must satisfy `rule`. Integer components
 * are normalized if the accessor says so. NaN or infinite values are an error. Messages read
 * "<what> <attribute> (accessor N): ...".
 */
std::vector<float> readFloats(const tinygltf::Model& model, int index, int components,
                              const std::string& what, const std::string& attribute,
                              ComponentRule rule = ComponentRule::Any);

/**
 * Reads a SCALAR accessor of UNSIGNED_BYTE, UNSIGNED_SHORT or UNSIGNED_INT as indices (the
 * only types the spec allows for primitive indices).
 */
std::vector<uint32_t> readIndices(const tinygltf::Model& model, int index, const std::string& what);

}  // namespace gilab::gltf
