#!/usr/bin/python3
"""Tests of scripts/cycles_crosscheck.py (the analysis half of the Cycles cross-check) on
synthetic renders with known per-sample noise, costs and bias. No Blender, no EXR files: a few
seconds.

    PYTHONPATH=scripts /usr/bin/python3 tests/crosscheck/test_analysis.py
    (ctest: CpuCyclesCrosscheck.AnalysisOnSyntheticRenders)
"""
import unittest

import numpy as np

import cycles_crosscheck as C  # scripts/ on PYTHONPATH (tests/CMakeLists.txt)

H, W = 96, 128


def truth():
    rng = np.random.default_rng(7)
    y = rng.uniform(0.02, 2.0, (H, W, 3))
    y[: H // 8] = 0.0  # a black band: only the 1e-2 in the weight keeps it finite
    return y


def renders(y, sigma, spp, cost, setup, rounds=2, gain=1.0, heavy=False, renderer="r",
            seed0=0):
    """Seed pairs of one renderer: per-sample std `sigma` per pixel, n = spp, marginal cost
    `cost` s/spp (wall; CPU twice that), `setup` s per render; images scaled by `gain`."""
    rng = np.random.default_rng(seed0)
    out = []
    for r in range(1, rounds + 1):
        for s in (2 * r - 1, 2 * r):
            if heavy:  # a mean of n samples of a skewed distribution, same variance
                noise = (rng.gamma(0.25, 1.0, (spp, H, W, 3)).mean(0) - 0.25) / 0.5
            else:
                noise = rng.standard_normal((H, W, 3)) / np.sqrt(spp)
            out.append({"renderer": renderer, "round": r, "seed": s, "spp": spp,
                        "image": gain * y + sigma * noise,
                        "seconds": setup + cost * spp, "cpu_seconds": 2 * (setup + cost * spp)})
        out.append({"renderer": renderer, "round": r, "seed": 1000, "spp": 1,
                    "image": gain * y, "seconds": setup + cost,
                    "cpu_seconds": 2 * (setup + cost)})
    return out


def expected_a(y, sigma):
    return float(np.mean(sigma**2 / (y * y + 1e-2)))


class TimeToTarget(unittest.TestCase):
    def setUp(self):
        self.y = truth()
        self.sg = 0.3 * np.sqrt(self.y + 0.05)  # gilab's per-sample std
        self.sc = 0.45 * np.sqrt(self.y + 0.05)  # Cycles': 2.25x the variance
        self.runs = (renders(self.y, self.sg, 256, 0.04, 0.1, renderer="gilab", seed0=1) +
                     renders(self.y, self.sc, 128, 0.05, 0.7, renderer="cycles", seed0=2))

    def test_a_cost_and_ratio(self):
        rows, ratios, spread = C.analyse(self.runs)
        for r in rows:
            sigma = self.sg if r["renderer"] == "gilab" else self.sc
            self.assertAlmostEqual(r["a"] / expected_a(self.y, sigma), 1.0, delta=0.03, msg=r)
            cost = 0.04 if r["renderer"] == "gilab" else 0.05
            self.assertAlmostEqual(r["s_per_spp"], cost, places=9)  # set-up removed exactly
            self.assertAlmostEqual(r["cpu_s_per_spp"], 2 * cost, places=9)
            self.assertAlmostEqual(r["seconds_to_target"], r["a"] / 1e-3 * cost, places=6)
        truth_ratio = (expected_a(self.y, self.sg) * 0.04) / (expected_a(self.y, self.sc) * 0.05)
        self.assertEqual(len(ratios), 2)
        for q in ratios:
            self.assertAlmostEqual(q["wall"] / truth_ratio, 1.0, delta=0.05)
            self.assertAlmostEqual(q["cpu"], q["wall"], places=9)
        self.assertLessEqual(spread["wall"][0], spread["wall"][1])

    def test_weights_do_not_come_from_the_pair(self):
        # Skewed noise (a mean of gamma samples): a pair's own mean correlates with its
        # difference, and weighting by it biases a low; the analysis' weights (the other
        # renders) do not
        y = truth()
        sigma = 0.5 * np.sqrt(y + 0.05)
        runs = (renders(y, sigma, 8, 0.04, 0.1, heavy=True, renderer="gilab", seed0=3) +
                renders(y, sigma, 8, 0.04, 0.1, heavy=True, renderer="cycles", seed0=4))
        rows, _, _ = C.analyse(runs)
        a_true = expected_a(y, sigma)
        pair = [r for r in runs if r["renderer"] == "gilab" and r["round"] == 1 and r["spp"] > 1]
        own = C.per_sample_mse(pair[0]["image"], pair[1]["image"], 8,
                               (pair[0]["image"] + pair[1]["image"]) / 2)
        ours = next(r["a"] for r in rows if r["renderer"] == "gilab" and r["round"] == 1)
        self.assertLess(abs(ours / a_true - 1.0), 0.05)
        self.assertLess(own / a_true, 0.9)  # the biased estimator, for contrast

    def test_missing_pair_is_an_error(self):
        runs = [r for r in self.runs if not (r["renderer"] == "cycles" and r["seed"] == 4)]
        with self.assertRaises(SystemExit) as e:
            C.analyse(runs)
        self.assertIn("round 2", str(e.exception))


def qmc_renders(y, sigma, counts, power, cost, setup, renderer, stage, seed0, rounds=1):
    """Seed pairs whose noise falls faster than 1/n, as a QMC sampler's may: the relMSE of an
    n-sample render is expected_a(y, sigma) / n**power. stage "ladder": one pair per count;
    "final": `rounds` rounds of a pair at counts[0] and a 1-sample render."""
    rng = np.random.default_rng(seed0)
    out = []
    for k, n in enumerate(counts if stage == "ladder" else counts * rounds):
        rnd = k + 1
        for s in (1, 2):
            noise = rng.standard_normal((H, W, 3)) / np.sqrt(float(n) ** power)
            out.append({"renderer": renderer, "round": rnd, "seed": 10 * rnd + s, "spp": n,
                        "image": y + sigma * noise, "stage": stage,
                        "seconds": setup + cost * n, "cpu_seconds": 2 * (setup + cost * n)})
        if stage == "final":
            out.append({"renderer": renderer, "round": rnd, "seed": 1000, "spp": 1, "image": y,
                        "stage": stage, "seconds": setup + cost,
                        "cpu_seconds": 2 * (setup + cost)})
    return out


class Ladder(unittest.TestCase):
    """Issue 49: the time to 1e-3 measured where 1e-3 is reached, not stretched by a 1/n law."""

    def test_interpolation_between_rungs_is_exact_for_a_power_law(self):
        rungs = [(n, 2.0 / n**1.25) for n in (256, 512, 1024, 2048, 4096)]
        n, slope = C.samples_to_target(rungs)
        self.assertAlmostEqual(slope, 1.25, places=9)
        self.assertAlmostEqual(n, 2000.0 ** (1 / 1.25), places=6)  # 2 / n^1.25 = 1e-3: 437
        self.assertIsNone(C.samples_to_target(rungs[:1]))  # not reached yet: go on
        with self.assertRaises(ValueError):  # no bracket below the target
            C.samples_to_target([(8192, 1e-4), (16384, 5e-5)])

    def test_noise_faster_than_1_over_n_fails_the_old_extrapolation(self):
        y = truth()
        sg, sc = 0.3 * np.sqrt(y + 0.05), 0.45 * np.sqrt(y + 0.05)
        power = {"gilab": 1.0, "cycles": 1.2}  # Cycles' noise falls faster than 1/n
        cost = {"gilab": 0.04, "cycles": 0.05}
        truth_spp = {"gilab": expected_a(y, sg) / 1e-3,
                     "cycles": (expected_a(y, sc) / 1e-3) ** (1 / 1.2)}
        ladder = {"gilab": [16, 32, 64, 128, 256, 512], "cycles": [16, 32, 64, 128, 256]}
        runs = []
        for name, sigma, seed in (("gilab", sg, 11), ("cycles", sc, 12)):
            runs += qmc_renders(y, sigma, ladder[name], power[name], cost[name], 0.5, name,
                                "ladder", seed)
            count = int(16 * np.ceil(truth_spp[name] / 16))
            runs += qmc_renders(y, sigma, [count], power[name], cost[name], 0.5, name, "final",
                                seed + 10, rounds=4)
        rows, ratios, spread = C.analyse_final(runs)
        self.assertEqual(len(ratios), 4)
        for r in rows:
            name = r["renderer"]
            self.assertAlmostEqual(r["spp_to_target"] / truth_spp[name], 1.0, delta=0.03, msg=r)
            self.assertAlmostEqual(r["s_per_spp"], cost[name], places=9)
            self.assertAlmostEqual(r["seconds_to_target"], r["spp_to_target"] * cost[name],
                                   places=6)
        truth_ratio = (truth_spp["gilab"] * 0.04) / (truth_spp["cycles"] * 0.05)
        for q in ratios:
            self.assertAlmostEqual(q["wall"] / truth_ratio, 1.0, delta=0.05)
        # The old method, a = n relMSE(n) at 16 spp stretched by 1/n, overestimates Cycles'
        # samples by (truth / 16)^0.2 (about 1.6x here) and so the ratio: it fails this noise
        cyc = next(r for r in rows if r["renderer"] == "cycles")
        self.assertGreater(cyc["extrapolated_spp"] / truth_spp["cycles"], 1.3)
        self.assertLess(spread["extrapolated_wall"][1] / truth_ratio, 0.8)
        gil = next(r for r in rows if r["renderer"] == "gilab")  # right for a 1/n sampler
        self.assertAlmostEqual(gil["extrapolated_spp"] / truth_spp["gilab"], 1.0, delta=0.03)


class Agreement(unittest.TestCase):
    def test_agreeing_and_biased_renderers(self):
        y = truth()
        sigma = 0.3 * np.sqrt(y + 0.05)
        g = renders(y, sigma, 256, 0.04, 0.1, renderer="gilab", seed0=5)
        same = C.agreement(g + renders(y, sigma, 256, 0.05, 0.7, renderer="cycles", seed0=6))
        dark = C.agreement(g + renders(y, sigma, 256, 0.05, 0.7, renderer="cycles", seed0=6,
                                       gain=0.98))
        for k in range(4):
            self.assertLess(abs(same["ratio_cycles_over_gilab"][k] - 1.0),
                            4 * same["ratio_sigma"][k])
            self.assertAlmostEqual(dark["ratio_cycles_over_gilab"][k], 0.98, delta=0.002)
            self.assertGreater(abs(dark["ratio_cycles_over_gilab"][k] - 1.0),
                               10 * dark["ratio_sigma"][k])
        # The relMSE between agreeing images is their noise; a 2 % bias adds to it
        self.assertAlmostEqual(same["rel_mse"] / same["rel_mse_expected_noise"], 1.0, delta=0.05)
        self.assertGreater(dark["rel_mse_minus_noise"], 0.1 * dark["rel_mse_expected_noise"])
        self.assertTrue(same["orientation_ok"])

    def test_flipped_camera_is_flagged(self):
        y = truth()
        sigma = 0.05 * np.sqrt(y + 0.05)
        g = renders(y, sigma, 64, 0.04, 0.1, renderer="gilab", seed0=8)
        c = renders(y, sigma, 64, 0.05, 0.7, renderer="cycles", seed0=9)
        for r in c:
            r["image"] = r["image"][:, ::-1]
        self.assertFalse(C.agreement(g + c)["orientation_ok"])


if __name__ == "__main__":
    unittest.main()
