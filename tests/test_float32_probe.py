"""The error-free transformations (templates/eft.j2) survive every float32 driver implc
runs: `implc probe`'s programs on llvmpipe (GLSL 330 and 450), lavapipe (WGSL through
wgpu), PoCL (OpenCL C float), HLSL through SPIR-V on llvmpipe, and Chromium's SwiftShader
(WebGL2 and WebGPU) return each lost bit exactly (two_sum(1, 2^-30)'s error is 2^-30,
two_prod(1+2^-12, 1+2^-12)'s is 2^-24, a compensated sum keeps the 1000 x 2^-25 plain
float32 drops), so a driver that folds them away fails here, not in a user's picture.

A driver that cannot run skips with its reason, and fails under CI=true. Each driver is
also shown a two_sum broken on purpose (its error computed as (a + b) - s, which is 0 in
any IEEE arithmetic): the probe must call it lost there, so a readback or check that
passed everything would fail.
"""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from conftest import _require

from implc.render.eft_probe import CASES, F32, OPS, Case, cases_for, probe_text, run_probe
from implc.targets import PROBES, get_target, resolve

ROOT = Path(__file__).resolve().parent.parent
NATIVE = [p for p in PROBES if p.backend not in ("webgl2", "webgpu")]
BROWSER = [p for p in PROBES if p.backend in ("webgl2", "webgpu")]


def ids(probes):
    return [f"{p.backend}-{p.flavor or p.target}" for p in probes]


def check_report(report):
    if report.unavailable:
        _require(f"the {report.probe.backend} driver", report.unavailable)
    print(report.render())
    lost = [o.render() for o in report.outcomes if o.relied_on and not o.ok]
    assert not lost, f"{report.probe.title} on {report.driver} lost:\n" + "\n".join(lost)
    eft_names = {o.case.eft for o in report.outcomes}
    assert {"two_sum", "fast_two_sum", "two_prod_split", "sum2", "plain_sum"} <= eft_names


def check_breaks(probe):
    """A two_sum that loses its bit by construction is reported lost on this driver."""
    case = Case("two_sum", 1.0, 2.0**-30)
    text = probe_text(probe, 1)
    rules = get_target(probe.target).rules(probe.flavor)
    good = "(a - (s - bb)) + (b - bb)"
    assert text.count(good) == 1, "templates/eft.j2's two_sum changed: update this test"
    broken = text.replace(good, "(a + b) - s")
    rows = np.array([(OPS["two_sum"], case.a, case.b, 0)], F32)
    (value, error), = resolve(probe.runner)(broken, rows)
    assert not case.check(F32(value), F32(error)), (probe.title, rules, value, error)


@pytest.mark.parametrize("probe", NATIVE, ids=ids(NATIVE))
def test_efts_survive_the_native_drivers(probe):
    check_report(run_probe(probe))
    check_breaks(probe)


@pytest.mark.parametrize("probe", BROWSER, ids=ids(BROWSER))
def test_efts_survive_chromium(browser, probe):
    from implc.render.browser_probe import use_browser

    use_browser(browser)
    check_report(run_probe(probe))
    check_breaks(probe)


def test_the_inputs_lose_bits_in_plain_float32():
    """The cases' premise, on the CPU: plain float32 loses what each EFT must recover
    (else a driver computing wider, or a folded EFT, could pass unnoticed)."""
    for case in CASES:
        a, b = F32(case.a), F32(case.b)
        if case.eft.startswith("two_prod"):
            plain = F32(a * b)
        elif case.eft in ("sum2", "plain_sum"):
            plain = a
            for _ in range(case.n):
                plain = F32(plain + b)
        else:
            plain = F32(a + b)
        assert float(plain) != case.exact(), case.label


def test_every_probe_has_its_flavours_cases():
    """two_prod_fma is probed exactly where the flavour has fma, and two_prod uses it
    only where the language promises one rounding (OpenCL C)."""
    for probe in PROBES:
        rules = get_target(probe.target).rules(probe.flavor)
        names = {c.eft for c in cases_for(probe.target, probe.flavor)}
        assert ("two_prod_fma" in names) == bool(rules.fma)
        text = probe_text(probe, 4)
        uses = "two_prod_fma(a, b);\n}" if rules.fma_exact else "two_prod_split(a, b);\n}"
        assert f"return {uses}" in text.replace("    ", ""), probe.title


def test_probe_command_reports_and_exits():
    """`implc probe -b gl` prints each EFT's error term and exits 0; an unknown backend
    is a usage error naming the choices."""
    run = subprocess.run([sys.executable, "-m", "implc", "probe", "-b", "gl"],
                         capture_output=True, text=True, cwd=ROOT, timeout=300)
    if run.returncode == 4:
        _require("an OpenGL context", run.stderr.strip())
    assert run.returncode == 0, run.stdout + run.stderr
    assert "two_sum(1.0, 2^-30)" in run.stdout and "error 2^-30 (exact: 2^-30)" in run.stdout
    assert "survive on 2 of 2" in run.stdout, run.stdout
    bad = subprocess.run([sys.executable, "-m", "implc", "probe", "-b", "gl,vulkan"],
                         capture_output=True, text=True, cwd=ROOT, timeout=60)
    assert bad.returncode == 2 and "unknown backend 'vulkan'" in bad.stderr, bad.stderr


def test_every_probe_names_what_exists():
    """Each probe's target, flavour, runner and driver exist (a renamed function or a
    flavour dropped from the registry fails here, not in `implc probe`)."""
    for probe in PROBES:
        target = get_target(probe.target)
        assert (probe.flavor or target.default_flavor) in target.flavors, probe
        assert callable(resolve(probe.runner)) and callable(resolve(probe.driver)), probe
        assert target.eft_probe, probe.target
