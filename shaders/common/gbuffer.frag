#version 460
#extension GL_GOOGLE_include_directive : require
// G-buffer layers (all RGBA32F; docs/shared_passes.md):
//   position  xyz world position, w = 1 (covered)
//   normal    xyz unit shading normal on the viewer's side, w = 1 if the viewer sees the front
//             face (counter-clockwise side of the geometric normal), 0 if the back face
//   albedo    rgb base colour x texture (linear), a = perceptual roughness
//   material  x metallic, y roughness, z material flags (MATERIAL_*), w triangle id + 1
//   emission  rgb emitted radiance toward the camera: Le on the front face, and on the back face
//             of double-sided emitters; 0 otherwise
// Background pixels keep the clear value 0 in every layer.
#define SCENE_IMPLICIT_LOD
#include "common/scene.glsl"
#include "common/gbuffer_pc.glsl"

layout(location = 0) in vec3 inWorldPos;
layout(location = 1) in vec3 inNormal;
layout(location = 2) in vec2 inUv;
layout(location = 3) flat in uint inTriangle;

layout(location = 0) out vec4 outPosition;
layout(location = 1) out vec4 outNormal;
layout(location = 2) out vec4 outAlbedo;
layout(location = 3) out vec4 outMaterial;
layout(location = 4) out vec4 outEmission;

void main() {
    Material m = fetchMaterial(inTriangle);
    vec4 baseColor = sampleBaseColor(m, inUv);
    if ((m.flags & MATERIAL_ALPHA_MASK) != 0u && baseColor.a < m.alphaCutoff) discard;

    // Facing from the geometric normal, independent of the rasteriser's winding convention.
    // The shading normal is then put on the viewer's side of the geometric normal.
    vec3 toViewer = pc.cameraPosition.xyz - inWorldPos;
    vec3 ng = triangleGeometricNormal(inTriangle);
    bool frontFace = dot(ng, toViewer) >= 0.0;
    vec3 ngViewer = frontFace ? ng : -ng;
    vec3 n = normalize(inNormal);
    if (dot(n, ngViewer) < 0.0) n = -n;

    vec2 metalRough = sampleMetalRough(m, inUv);
    bool emits = frontFace || (m.flags & MATERIAL_DOUBLE_SIDED) != 0u;

    outPosition = vec4(inWorldPos, 1.0);
    outNormal = vec4(n, frontFace ? 1.0 : 0.0);
    outAlbedo = vec4(baseColor.rgb, metalRough.y);
    outMaterial = vec4(metalRough.x, metalRough.y, float(m.flags), float(inTriangle + 1u));
    outEmission = vec4(emits ? sampleEmission(m, inUv) : vec3(0.0), 0.0);
}
