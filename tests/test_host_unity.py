"""The Unity host (implc/hosts.py, templates/hosts/unity/): its Custom Function file, as
Shader Graph calls it (Name_float / Name_half(inputs..., out outputs...), the outputs
declared as locals first: templates/hosts/unity/harness.hlsl.j2), compiled by two HLSL
front ends (glslang and Slang) and rendered through SPIR-V, against implc's own GL render
of the same view: SSIM >= 0.99 and hit masks agreeing on >= 99.5 % of the pixels (the
browser tests' bounds, tests/test_browser.py), t within 1e-4 where both hit.
Unity itself does not run here (docs/guide/hosts.md "Unity (Shader Graph)")."""

from __future__ import annotations

import pytest
from conftest import require_tool
from host_harness import (
    FRONT_ENDS,
    clashing_surface,
    compile_front,
    exported,
    harness,
    honours_t_far,
    renders_like_implc,
)

from implc.emit import param_uniforms

SHOT = "host-unity.png"  # docs/guide/hosts.md's picture, kept with IMPLC_SCREENSHOTS=DIR


@pytest.mark.parametrize("front", FRONT_ENDS)
@pytest.mark.parametrize("real", ["float", "half"])
def test_the_node_file_compiles_as_shader_graph_calls_it(tmp_path, front, real):
    """Both precisions' functions, called with the node's locals, by both front ends."""
    require_tool("glslangValidator")
    files, surface = exported("unity", tmp_path, "torus")
    (name,) = files
    compile_front(front, harness("unity", tmp_path / name, name.removesuffix(".hlsl"),
                                 param_uniforms(surface, "hlsl", "library"), real=real),
                  tmp_path)


@pytest.mark.parametrize("front", FRONT_ENDS)
@pytest.mark.parametrize("example", ["torus", "cross-cap"])
def test_the_node_renders_like_implc(tmp_path, front, example):
    """The node's picture, its hits and its t are implc's own (GL) for the same view;
    a moved parameter (a node input) moves the picture as it moves implc's."""
    files, surface = exported("unity", tmp_path, example)
    (name,) = files
    controls = param_uniforms(surface, "hlsl", "library")
    text = harness("unity", tmp_path / name, name.removesuffix(".hlsl"), controls)
    renders_like_implc(text, tmp_path, front, surface, controls, f"unity {example}",
                       SHOT if front == "glslang" and example == "torus" else "")


def test_the_half_function_renders_like_implc(tmp_path):
    """Name_half's wiring (to float and back) through glslang, where half is float (no
    16-bit types asked for): so its inputs and outputs, not 16-bit precision, are what
    this checks. Slang's half is 16-bit, which GLSL 330 cannot take: compiled only."""
    files, surface = exported("unity", tmp_path, "torus")
    (name,) = files
    controls = param_uniforms(surface, "hlsl", "library")
    text = harness("unity", tmp_path / name, name.removesuffix(".hlsl"), controls,
                   real="half")
    renders_like_implc(text, tmp_path, "glslang", surface, controls, "unity torus, _half")


def test_parameters_named_as_the_nodes_own_names_are_renamed_inputs(tmp_path):
    """Parameters t, out and T (a local, an HLSL keyword, an output) are inputs t_in,
    out_in and T_in, and each reaches its own parameter (the last, t, moved)."""
    surface = clashing_surface()
    files, _ = exported("unity", tmp_path, surface)
    (name,) = files
    head = "\n".join(files[name].splitlines()[:30])
    assert all(f"{p}_in (Float: the parameter {p};" in head for p in ("t", "out", "T"))
    controls = param_uniforms(surface, "hlsl", "library")
    text = harness("unity", tmp_path / name, name.removesuffix(".hlsl"), controls)
    renders_like_implc(text, tmp_path, "glslang", surface, controls, "unity clash")


def test_the_node_searches_no_farther_than_tfar(tmp_path):
    """TFar (e.g. the scene depth) cuts the search: nearer hits stay, farther ones go."""
    files, surface = exported("unity", tmp_path, "torus")
    (name,) = files
    controls = param_uniforms(surface, "hlsl", "library")
    text = harness("unity", tmp_path / name, name.removesuffix(".hlsl"), controls)
    honours_t_far(text, tmp_path, surface, controls, "unity torus")
