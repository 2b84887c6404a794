#pragma once
/**
 * glTF accessor decoding: every component type (normalized integers mapped per the spec),
 * byte strides, accessors without a buffer view (zeros) and sparse accessors. Bounds are
 * checked against the buffers; errors name `what` (file, mesh, attribute).
 */
#include <cstdint>
#include <string>
#include <vector>

namespace tinygltf {
class Model;
}

namespace gilab::gltf {

/**
 * Reads accessor `index` as `components` floats per element (SCALAR = 1 ... VEC4 = 4); the
 * accessor's type must match. Integer components are normalized if the accessor says so.
 */
std::vector<float> readFloats(const tinygltf::Model& model, int index, int components,
                              const std::string& what);

/** Reads a SCALAR integer accessor as indices; negative values are an error. */
std::vector<uint32_t> readIndices(const tinygltf::Model& model, int index, const std::string& what);

}  // namespace gilab::gltf
