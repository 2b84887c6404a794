# Blender-side half of scripts/cycles_crosscheck.sh (optional; not part of the build or CI).
#
# Renders a glTF scene with Cycles the way gilab's reference path tracer sees it: every
# material becomes Diffuse(base colour) + Emission(emissiveFactor x emissiveStrength), read
# from the glTF JSON itself; the base colour is baseColorFactor, or with --textures whatever the
# glTF importer linked to its Principled BSDF's Base Color (the texture times the factor);
# gilab's camera and directional lights (a scene description's "camera" and "lights", in glTF
# Y-up coordinates; a directional light becomes a sun of angle 0 and strength colour x
# intensity, W/m^2 as docs/conventions.md); rays through pixel centres, no adaptive sampling,
# denoising or clamping; black world. Writes a linear 32-bit float RGB OpenEXR and, beside it, a
# JSON with the render's wall and CPU time. The figures the cross-check derives from it belong
# in docs/reference.md ("Measured: ground-truth speed").
#
#   blender -b --factory-startup -t T --python scripts/cycles_render.py -- \
#       --scene DIR/scene.json --out DIR/cycles_16.exr --width 256 --height 256 --samples 16 \
#       --seed 1 --threads T [--textures [--linear-textures]]
import argparse
import json
import math
import os
import re
import sys
import time

import bpy
from mathutils import Matrix, Vector

argv = sys.argv[sys.argv.index("--") + 1:] if "--" in sys.argv else []
ap = argparse.ArgumentParser(prog="cycles_render.py")
ap.add_argument("--scene", required=True, help="gilab scene description (.json): gltf, camera")
ap.add_argument("--out", required=True, help="output .exr")
ap.add_argument("--width", type=int, default=256)
ap.add_argument("--height", type=int, default=256)
ap.add_argument("--textures", action="store_true",
                help="keep the importer's base-colour textures (else the factors only)")
ap.add_argument("--linear-textures", action="store_true",
                help="with --textures: decode every sRGB texel to linear float before Cycles "
                     "filters it (as gilab does), instead of Cycles' filter-then-decode")
ap.add_argument("--pixel-filter", choices=("center", "box"), default="center",
                help="center: rays through pixel centres (gilab's --pixel-filter center); box: "
                     "uniform over the pixel (gilab's box)")
ap.add_argument("--samples", type=int, default=16)
ap.add_argument("--seed", type=int, default=1)
ap.add_argument("--threads", type=int, default=2)
ap.add_argument("--max-bounces", type=int, default=64)
ap.add_argument("--min-light-bounces", type=int, default=0,
                help="Cycles' Russian roulette starts after this bounce (0 = Cycles' default)")
args = ap.parse_args(argv)

with open(args.scene) as f:
    desc = json.load(f)
gltf_path = os.path.join(os.path.dirname(os.path.abspath(args.scene)), desc["gltf"])
with open(gltf_path) as f:
    gltf = json.load(f)

# Debian's Blender 3.4.1 glTF importer still uses np.bool, which numpy 1.24 removed.
import numpy  # noqa: E402
if "bool" not in numpy.__dict__:
    numpy.bool = bool

# An empty scene, then the glTF.
bpy.ops.wm.read_factory_settings(use_empty=True)
bpy.ops.import_scene.gltf(filepath=gltf_path)
scene = bpy.context.scene


def imported_base_colour(mat):
    """The socket the importer linked to its Principled BSDF's Base Color (texture x factor),
    or None."""
    if mat is None or not mat.use_nodes:
        return None
    for node in mat.node_tree.nodes:
        if node.type == "BSDF_PRINCIPLED" and node.inputs["Base Color"].is_linked:
            return node.inputs["Base Color"].links[0].from_socket
    return None


def diffuse_emission_material(name, gm, imported):
    """Diffuse BSDF + Emission from the glTF material dict gm (glTF defaults when absent). With
    --textures the imported material `imported` is rebuilt in place, keeping its base-colour
    texture nodes."""
    pbr = gm.get("pbrMetallicRoughness", {})
    base = pbr.get("baseColorFactor", [1, 1, 1, 1])
    emissive = gm.get("emissiveFactor", [0, 0, 0])
    strength = gm.get("extensions", {}).get("KHR_materials_emissive_strength", {}).get(
        "emissiveStrength", 1.0)
    if pbr.get("metallicFactor", 1.0) != 0.0 or pbr.get("roughnessFactor", 1.0) != 1.0 or \
            "metallicRoughnessTexture" in pbr:
        sys.exit(f"cycles_render: material {name} is not Lambertian (metallic 0, roughness 1); "
                 "the cross-check rebuilds every material as a diffuse BSDF")
    if gm.get("alphaMode", "OPAQUE") != "OPAQUE":
        sys.exit(f"cycles_render: material {name}: alphaMode {gm['alphaMode']} is not supported")
    textured = "baseColorTexture" in pbr
    if "emissiveTexture" in gm or (textured and not args.textures):
        print(f"cycles_render: material {name}: textures ignored (factors only)")
    colour = imported_base_colour(imported) if textured and args.textures else None
    if textured and args.textures and colour is None:
        sys.exit(f"cycles_render: material {name}: the importer linked no base-colour texture")
    if colour is not None:
        mat = imported  # keep its texture and UV nodes, replace the rest
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        keep = set()
        stack = [colour.node]
        while stack:  # the base colour's upstream nodes
            node = stack.pop()
            if node.name not in keep:
                keep.add(node.name)
                stack += [link.from_node for i in node.inputs for link in i.links]
        for node in list(nodes):
            if node.name not in keep:
                nodes.remove(node)
    else:
        mat = bpy.data.materials.new(name + ".crosscheck")
        mat.use_nodes = True
        nodes, links = mat.node_tree.nodes, mat.node_tree.links
        nodes.clear()
    diffuse = nodes.new("ShaderNodeBsdfDiffuse")
    diffuse.inputs["Color"].default_value = (*base[:3], 1.0)
    if colour is not None:
        links.new(colour, diffuse.inputs["Color"])
    diffuse.inputs["Roughness"].default_value = 0.0  # 0 = Lambertian (no Oren-Nayar)
    emission = nodes.new("ShaderNodeEmission")
    emission.inputs["Color"].default_value = (*emissive[:3], 1.0)
    emission.inputs["Strength"].default_value = strength
    add = nodes.new("ShaderNodeAddShader")
    out = nodes.new("ShaderNodeOutputMaterial")
    links.new(diffuse.outputs["BSDF"], add.inputs[0])
    links.new(emission.outputs["Emission"], add.inputs[1])
    links.new(add.outputs["Shader"], out.inputs["Surface"])
    print(f"cycles_render: {name}: diffuse {'texture x ' if colour else ''}{base[:3]}, "
          f"emission {emissive[:3]} x {strength}")
    return mat


# Replace every material by name (the importer may add ".001" suffixes); primitives without a
# material get glTF's default material (white, no emission).
by_name = {m.get("name"): m for m in gltf.get("materials", [])}
replaced = {}
for obj in scene.objects:
    if obj.type != "MESH":
        continue
    if not obj.material_slots:
        obj.data.materials.append(None)
    for slot in obj.material_slots:
        name = re.sub(r"\.\d{3}$", "", slot.material.name) if slot.material else "(default)"
        if slot.material and name not in by_name:
            sys.exit(f"cycles_render: material {slot.material.name} is not in {gltf_path}")
        if name not in replaced:
            replaced[name] = diffuse_emission_material(name, by_name.get(name, {}), slot.material)
        slot.material = replaced[name]


def linearised(image):
    """A float copy of an 8-bit sRGB image with every texel decoded (IEC 61966-2-1) before any
    filtering: Cycles keeps 8-bit sRGB images as bytes and decodes after its bilinear filter
    (svm_image_texture's NODE_IMAGE_COMPRESS_AS_SRGB), gilab decodes each texel first."""
    w, h = image.size
    px = numpy.empty(w * h * 4, dtype=numpy.float32)
    image.pixels.foreach_get(px)  # the stored values, sRGB-encoded, in [0, 1]
    rgb = px.reshape(-1, 4)[:, :3].astype(numpy.float64)
    px.reshape(-1, 4)[:, :3] = srgb_to_linear(rgb)
    out = bpy.data.images.new(image.name + ".linear", w, h, alpha=True, float_buffer=True)
    out.colorspace_settings.name = "Linear"
    out.pixels.foreach_set(px)
    out.pack()
    return out


if args.linear_textures:
    sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
    from gltf_mean_factors import srgb_to_linear  # noqa: E402 (one sRGB decode for both)
    if not args.textures:
        sys.exit("cycles_render: --linear-textures needs --textures")
    copies = {}
    for mat in replaced.values():
        for node in (mat.node_tree.nodes if mat and mat.use_nodes else []):
            if node.type == "TEX_IMAGE" and node.image is not None:
                if node.image.colorspace_settings.name != "sRGB":
                    sys.exit(f"cycles_render: image {node.image.name} is "
                             f"{node.image.colorspace_settings.name}, not sRGB")
                if node.image.name not in copies:
                    copies[node.image.name] = linearised(node.image)
                node.image = copies[node.image.name]
    print(f"cycles_render: {len(copies)} textures decoded to linear float before filtering")

# Camera: glTF Y-up -> Blender Z-up as the importer does it, (x, y, z) -> (x, -z, y).
cam_desc = desc["camera"]


def to_blender(v):
    return Vector((v[0], -v[2], v[1]))


pos, target, up = (to_blender(cam_desc.get(k, [0, 1, 0])) for k in ("position", "target", "up"))
cam_data = bpy.data.cameras.new("crosscheck")
cam_data.sensor_fit = "VERTICAL"
cam_data.angle_y = math.radians(cam_desc["vfov_deg"])
cam_data.clip_start, cam_data.clip_end = 1e-3, 1e4
cam = bpy.data.objects.new("crosscheck", cam_data)
scene.collection.objects.link(cam)
cam.location = pos
forward = (target - pos).normalized()
right = forward.cross(up).normalized()
true_up = right.cross(forward)
# Blender's camera looks along its local -Z with +Y up: columns (right, up, -forward).
rot = Matrix((right, true_up, -forward)).transposed()
cam.rotation_euler = rot.to_euler()
scene.camera = cam

# The scene description's lights (glTF lights are not used by gilab's cross-check scenes).
for obj in [o for o in scene.objects if o.type == "LIGHT"]:
    bpy.data.objects.remove(obj)
for i, light in enumerate(desc.get("lights", [])):
    if light.get("type") != "directional":
        sys.exit(f"cycles_render: light {i}: type {light.get('type')} is not supported "
                 "(directional only)")
    d = to_blender(light["direction"]).normalized()  # the direction light travels
    colour = light.get("color", [1, 1, 1])
    sun = bpy.data.lights.new(light.get("name", f"sun{i}"), "SUN")
    sun.energy = float(light.get("intensity", 1.0))  # irradiance, W/m^2
    sun.color = colour[:3]
    sun.angle = 0.0
    if hasattr(sun, "cycles"):
        sun.cycles.cast_shadow = True
    obj = bpy.data.objects.new(sun.name, sun)
    scene.collection.objects.link(obj)
    obj.rotation_euler = d.to_track_quat("-Z", "Y").to_euler()  # a sun shines along its -Z
    print(f"cycles_render: sun {sun.name}: direction {tuple(d)}, {sun.energy} x {colour[:3]}")

# Black world.
world = bpy.data.worlds.new("crosscheck")
world.use_nodes = True
bg = world.node_tree.nodes["Background"]
bg.inputs["Color"].default_value = (0, 0, 0, 1)
bg.inputs["Strength"].default_value = 0.0
scene.world = world

# Render settings.
r, c = scene.render, scene.cycles
r.engine = "CYCLES"
c.device = "CPU"
r.threads_mode, r.threads = "FIXED", args.threads
r.resolution_x, r.resolution_y = args.width, args.height
r.resolution_percentage = 100
r.pixel_aspect_x = r.pixel_aspect_y = 1
r.film_transparent = False
r.use_compositing = r.use_sequencer = False
c.samples = args.samples
c.use_adaptive_sampling = False
c.use_denoising = False
c.seed, c.use_animated_seed = args.seed, False
c.sample_clamp_direct = c.sample_clamp_indirect = 0.0
c.max_bounces = args.max_bounces
for k in ("diffuse_bounces", "glossy_bounces", "transmission_bounces", "volume_bounces",
          "transparent_max_bounces"):
    setattr(c, k, args.max_bounces)
c.caustics_reflective = c.caustics_refractive = False  # no specular anywhere: irrelevant
c.blur_glossy = 0.0
c.min_light_bounces = args.min_light_bounces
if hasattr(c, "light_sampling_threshold"):
    c.light_sampling_threshold = 0.0
# Rays (almost) through pixel centres, like gilab's --pixel-filter center. Not "BOX": Blender
# hands Cycles a box filter always 1 pixel wide, whatever filter_width says (which is exactly
# gilab's --pixel-filter box). A Gaussian of the minimum width 0.01 keeps every ray within
# 0.015 pixel of the centre.
if args.pixel_filter == "box":
    c.pixel_filter_type = "BOX"
    c.filter_width = 1.0
else:
    c.pixel_filter_type = "GAUSSIAN"
    c.filter_width = 0.01
c.film_exposure = 1.0
scene.view_settings.view_transform = "Standard"
scene.view_settings.look = "None"
scene.view_settings.exposure = 0.0
scene.view_settings.gamma = 1.0
img = r.image_settings
img.file_format, img.color_mode, img.color_depth, img.exr_codec = "OPEN_EXR", "RGB", "32", "ZIP"
r.filepath = os.path.abspath(args.out)
r.use_file_extension = False

t0, c0 = time.perf_counter(), time.process_time()
bpy.ops.render.render(write_still=True)
seconds, cpu_seconds = time.perf_counter() - t0, time.process_time() - c0

info = {
    "renderer": "cycles",
    "blender_version": bpy.app.version_string,
    "samples": args.samples,
    "seed": args.seed,
    "threads": args.threads,
    "resolution": [args.width, args.height],
    "seconds": seconds,
    "cpu_seconds": cpu_seconds,
    "seconds_per_sample": seconds / args.samples,
    "settings": {"device": "CPU", "max_bounces": args.max_bounces, "pixel_filter":
                 "box 1 px" if args.pixel_filter == "box" else "gaussian 0.01",
                 "adaptive": False, "denoise": False, "clamp": 0, "textures": args.textures,
                 "linear_textures": args.linear_textures,
                 "min_light_bounces": c.min_light_bounces,
                 "sampling_pattern": c.sampling_pattern},
}
with open(os.path.splitext(args.out)[0] + ".json", "w") as f:
    json.dump(info, f, indent=2)
print(f"cycles_render: {args.samples} spp in {seconds:.3f} s -> {args.out}")
