"""`implc export --host H` and `Surface.export(H)` (issue 46): the host registry
(implc/hosts.py) and its assembly (implc/export.py). Each host's own proof, by the host's
code where it runs here, is in its own test file; these are the rules every host keeps."""

from __future__ import annotations

import pytest
from conftest import require_tool
from test_cli import implc

import implc as api
from implc.errors import OptionError
from implc.hosts import HOSTS


def test_an_unknown_host_is_a_usage_error_with_a_did_you_mean(tmp_path):
    proc = implc("export", "torus", "--host", "unty", "-o", str(tmp_path / "out"))
    assert proc.returncode == 2
    assert "unknown host 'unty'; did you mean 'unity'?" in proc.stderr
    assert not (tmp_path / "out").exists()
    with pytest.raises(OptionError, match="did you mean 'unity'"):
        api.Surface.example("torus").export("unty")


@pytest.mark.parametrize("host", sorted(HOSTS))
def test_a_precision_the_host_lacks_is_refused_with_the_reason(host, tmp_path):
    if "double" in HOSTS[host].precisions:
        pytest.skip(f"{host} takes double")
    proc = implc("export", "torus", "--host", host, "--precision", "double",
                 "-o", str(tmp_path))
    assert proc.returncode == 2 and "cannot take it" in proc.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("host", sorted(HOSTS))
def test_every_host_writes_its_files_with_how_to_use_them(host, tmp_path):
    """Its files, deterministic, the parameters named, 'How to use it' at the top."""
    first = api.Surface.example("torus").export(host)
    again = api.Surface.example("torus").export(host)
    assert first.files == again.files
    proc = implc("export", "torus", "--host", host, "-o", str(tmp_path))
    assert proc.returncode == 0, proc.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(first.files)
    head = "\n".join(first.main.splitlines()[:30])
    assert "How to use it" in head
    for name in ("R", "r"):  # the torus's parameters, as the host's controls
        assert name in head


def test_the_unity_node_file_compiles_as_shader_graph_calls_it(tmp_path):
    """The Custom Function node calls Name_float(inputs..., out ...); a pixel shader that
    does the same compiles with glslang's HLSL front end."""
    glslang = require_tool("glslangValidator")
    text = api.Surface.example("torus").export("unity").files["Torus.hlsl"]
    harness = tmp_path / "harness.hlsl"
    harness.write_text(text + """
float4 main(float4 pos : SV_Position) : SV_Target {
    bool hit; float t; float3 n; float3 c;
    Torus_float(float3(0.0, 0.0, 4.0), float3(0.0, 0.0, -1.0), 2.0, 6.0, 1.0, 0.35,
                hit, t, n, c);
    return float4(c, hit ? 1.0 : 0.0);
}
""")
    import subprocess

    proc = subprocess.run([glslang, "-V", "-D", "-S", "frag", "-e", "main", str(harness),
                           "-o", str(tmp_path / "h.spv")], capture_output=True, text=True,
                          timeout=120)
    assert proc.returncode == 0, proc.stdout + proc.stderr
