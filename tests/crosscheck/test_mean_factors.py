#!/usr/bin/python3
"""Tests of scripts/gltf_mean_factors.py (issue 49): a glTF copy whose base-colour textures are
replaced by their mean linear colour, the untextured control of the Cycles cross-check.

    /usr/bin/python3 tests/crosscheck/test_mean_factors.py
    (ctest: CpuCyclesCrosscheck.MeanFactorsReplaceTextures)
"""
import json
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np
import OpenImageIO as oiio

SCRIPT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "scripts",
                      "gltf_mean_factors.py")


def srgb_decode(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


class MeanFactors(unittest.TestCase):
    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory()
        d = self.tmp.name
        os.makedirs(os.path.join(d, "src"))
        os.makedirs(os.path.join(d, "out", "deeper"))
        # A 2x1 RGB texture: black and white texels, so the mean of the decoded texels (0.5)
        # differs from the decoded mean texel (0.214) by more than any rounding
        px = np.array([[[0, 0, 0], [255, 255, 255]]], dtype=np.uint8)
        out = oiio.ImageOutput.create(os.path.join(d, "src", "t.png"))
        out.open(os.path.join(d, "src", "t.png"), oiio.ImageSpec(2, 1, 3, "uint8"))
        out.write_image(px)
        out.close()
        # A 1x1 RGBA texture (sRGB 128 -> 0.2158605), alpha 51 / 255 = 0.2
        px = np.array([[[128, 128, 128, 51]]], dtype=np.uint8)
        out = oiio.ImageOutput.create(os.path.join(d, "src", "a.png"))
        spec = oiio.ImageSpec(1, 1, 4, "uint8")
        spec.attribute("oiio:UnassociatedAlpha", 1)  # store the colour as given, not divided
        out.open(os.path.join(d, "src", "a.png"), spec)
        out.write_image(px)
        out.close()
        with open(os.path.join(d, "src", "s.bin"), "wb") as f:
            f.write(b"\0" * 12)
        self.gltf = {
            "asset": {"version": "2.0"},
            "buffers": [{"uri": "s.bin", "byteLength": 12}],
            "images": [{"uri": "t.png"}, {"uri": "a.png"}],
            "textures": [{"source": 0}, {"source": 1}],
            "materials": [
                {"name": "textured", "pbrMetallicRoughness": {
                    "baseColorTexture": {"index": 0}, "baseColorFactor": [1.0, 0.5, 0.25, 1.0]}},
                {"name": "alpha", "pbrMetallicRoughness": {"baseColorTexture": {"index": 1}}},
                {"name": "plain", "pbrMetallicRoughness": {"baseColorFactor": [0.3, 0.2, 0.1, 1]}},
            ],
        }
        self.src = os.path.join(d, "src", "scene.gltf")
        json.dump(self.gltf, open(self.src, "w"))
        self.dst = os.path.join(d, "out", "deeper", "flat.gltf")

    def tearDown(self):
        self.tmp.cleanup()

    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def test_factor_is_the_mean_of_decoded_texels_times_the_factor(self):
        r = self.run_script(self.src, self.dst)
        self.assertEqual(r.returncode, 0, r.stderr)
        out = json.load(open(self.dst))
        textured, alpha, plain = (m["pbrMetallicRoughness"] for m in out["materials"])
        self.assertNotIn("baseColorTexture", textured)
        self.assertNotIn("baseColorTexture", alpha)
        mean = 0.5 * (srgb_decode(0.0) + srgb_decode(1.0))  # 0.5, not decode(0.5) = 0.214
        np.testing.assert_allclose(textured["baseColorFactor"],
                                   [mean, 0.5 * mean, 0.25 * mean, 1.0], rtol=1e-6)
        np.testing.assert_allclose(alpha["baseColorFactor"],
                                   [srgb_decode(128 / 255)] * 3 + [0.2], rtol=1e-6)
        self.assertEqual(plain["baseColorFactor"], [0.3, 0.2, 0.1, 1])

    def test_uris_stay_relative_and_reach_the_source_files(self):
        self.assertEqual(self.run_script(self.src, self.dst).returncode, 0)
        out = json.load(open(self.dst))
        for uri in [out["buffers"][0]["uri"]] + [im["uri"] for im in out["images"]]:
            self.assertFalse(os.path.isabs(uri), uri)  # tinygltf joins uris to the folder
            self.assertTrue(os.path.isfile(os.path.join(os.path.dirname(self.dst), uri)), uri)

    def test_bad_input_names_the_file(self):
        missing = os.path.join(self.tmp.name, "nope.gltf")
        r = self.run_script(missing, self.dst)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("nope.gltf", r.stderr)
        os.remove(os.path.join(self.tmp.name, "src", "t.png"))
        r = self.run_script(self.src, self.dst)
        self.assertNotEqual(r.returncode, 0)
        self.assertIn("t.png", r.stderr)


if __name__ == "__main__":
    unittest.main()
