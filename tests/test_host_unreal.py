"""The Unreal host (implc/hosts.py, templates/hosts/unreal/): the Custom node's Code
(STEM_CustomNode.hlsl) inside the function Unreal's material translator wraps it in
(`MaterialFloat3 CustomExpression0(FMaterialPixelParameters Parameters, inputs...,
inout additional outputs...) { <Code> }`, the .ush from Include File Paths #included
first, Unreal's types defined minimally: templates/hosts/unreal/harness.hlsl.j2),
compiled by two HLSL front ends (glslang and Slang) and rendered through SPIR-V, against
implc's own GL render of the same view, with tests/test_host_unity.py's bounds.
Unreal itself does not run here (docs/guide/hosts.md "Unreal Engine (Custom node)")."""

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

SHOT = "host-unreal.png"  # docs/guide/hosts.md's picture, kept with IMPLC_SCREENSHOTS=DIR


def unreal_harness(tmp_path, example: str) -> tuple[str, object, list]:
    files, surface = exported("unreal", tmp_path, example)
    code, ush = files  # the node's Code first, then its include
    assert code.endswith("_CustomNode.hlsl") and ush.endswith(".ush")
    controls = param_uniforms(surface, "hlsl", "library")
    text = harness("unreal", tmp_path / ush, ush.removesuffix(".ush"), controls,
                   body=files[code])
    return text, surface, controls


@pytest.mark.parametrize("front", FRONT_ENDS)
def test_the_custom_node_compiles_as_unreal_wraps_it(tmp_path, front):
    require_tool("glslangValidator")
    text, _, _ = unreal_harness(tmp_path, "torus")
    compile_front(front, text, tmp_path)


@pytest.mark.parametrize("front", FRONT_ENDS)
@pytest.mark.parametrize("example", ["torus", "cross-cap"])
def test_the_custom_node_renders_like_implc(tmp_path, front, example):
    """The node's colour, Hit and T are implc's own (GL) for the same view; a moved
    parameter (a node input) moves the picture as it moves implc's."""
    text, surface, controls = unreal_harness(tmp_path, example)
    renders_like_implc(text, tmp_path, front, surface, controls, f"unreal {example}",
                       SHOT if front == "glslang" and example == "torus" else "")


def test_parameters_named_as_the_nodes_own_names_are_renamed_inputs(tmp_path):
    """Parameters t, out and T (a local, an HLSL keyword, an output) are the Custom
    node's inputs t_in, out_in and T_in, each reaching its own parameter."""
    surface = clashing_surface()
    files, _ = exported("unreal", tmp_path, surface)
    code, ush = files
    assert files[code].rstrip().endswith("TNear, TFar, T_in, out_in, t_in, Hit, T, Normal);")
    controls = param_uniforms(surface, "hlsl", "library")
    text = harness("unreal", tmp_path / ush, ush.removesuffix(".ush"), controls,
                   body=files[code])
    renders_like_implc(text, tmp_path, "glslang", surface, controls, "unreal clash")


def test_the_custom_node_searches_no_farther_than_tfar(tmp_path):
    """TFar (e.g. the scene depth) cuts the search: nearer hits stay, farther ones go."""
    text, surface, controls = unreal_harness(tmp_path, "torus")
    honours_t_far(text, tmp_path, surface, controls, "unreal torus")
