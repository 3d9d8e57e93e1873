"""What a bench run is: its configurations, its cells and the run that holds them.

Plain records, below both the measurement (`measure.py` fills them) and the report
(`report.py` formats them), so that neither of those needs the other's types.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

from ..errors import InputError
from ..surface import Surface

# Table 1's columns in the paper's order, then `sign` (not in the paper; informative) and
# `exact` (implc's root isolation, beyond the paper).
DEFAULT_METHODS: tuple[str, ...] = ("taylor", "curvature", "hessian-approx", "hessian", "sign",
                                    "exact")
CONFIG_NAMES: tuple[str, ...] = ("paper", "equal", "taylor2", "extremum")
EQUAL_STEP = 0.002  # the paper's hessian step, given to every method in `equal`


@dataclass(frozen=True)
class BenchConfig:
    """A set of constant overrides and the methods they are measured on."""

    name: str
    title: str
    overrides: Mapping[str, object]
    methods: tuple[str, ...] | None = None  # None: every selected method

    def applies_to(self, selected: Sequence[str]) -> list[str]:
        return [m for m in selected if self.methods is None or m in self.methods]


def make_configs(names: Sequence[str], equal_step: float = EQUAL_STEP) -> list[BenchConfig]:
    """The named configurations, in the order given (see implc/bench/__init__.py)."""
    known = {
        "paper": BenchConfig(
            "paper", "the paper's constants: b = 0.01 (hessian 0.002), tau1 = tau2 = tau3 = 0.01",
            {}),
        "equal": BenchConfig(
            "equal", f"equal step: b = {equal_step:g} for every method, tau as in the paper",
            {"step": equal_step}),
        "taylor2": BenchConfig(
            "taylor2", "Eq. 4 consistent (h^2/8, F''(t1) in r) at the paper's constants; "
            "taylor is unaffected and re-timed as the fps baseline",
            {"taylor2": "consistent"}, methods=("taylor", "hessian-approx", "hessian", "exact")),
        "extremum": BenchConfig(
            "extremum", "implc's extremum test (consistent Eq. 4 plus the extremum of each "
            "end's quadratic model) at the paper's constants; taylor re-timed as the baseline",
            {"taylor2": "extremum"}, methods=("taylor", "hessian-approx", "hessian", "exact")),
    }
    configs = []
    for name in names:
        if name not in known:
            raise InputError(f"unknown configuration '{name}'; choose from {', '.join(known)}")
        if name not in (c.name for c in configs):
            configs.append(known[name])
    return configs


@dataclass
class Cell:
    """One surface x method x configuration measurement."""

    fps: float
    frame_seconds: list[float]
    setup_seconds: float  # implc's emit and the driver's program build
    compile_seconds: float  # the program's first use, where llvmpipe compiles it
    metrics: dict
    render: str  # PNG path relative to the output directory
    ratio_to_taylor: float | None = None

    def as_json(self) -> dict:
        return {
            "fps": self.fps,
            "ratio_to_taylor": self.ratio_to_taylor,
            "frame_seconds": self.frame_seconds,
            "setup_seconds": self.setup_seconds,
            "compile_seconds": self.compile_seconds,
            **self.metrics,
            "render": self.render,
        }


@dataclass
class BenchRun:
    """Everything measured (report.table_json(run) is table.json)."""

    size: int
    frames: int
    backend: str
    methods: list[str]
    configs: list[BenchConfig]
    surfaces: dict[str, Surface]
    machine: dict
    reference_seconds: dict[str, float] = field(default_factory=dict)
    cells: dict[tuple[str, str, str], Cell] = field(default_factory=dict)  # (config, surf, m)
    baseline: bool = False  # time the hand-written programs too (implc/baseline.py)
    # the hand-written programs, timed in turns with the generated ones
    baseline_cells: dict[tuple[str, str, str], Cell] = field(default_factory=dict)
    tiles: dict[tuple[str, str, str], object] = field(default_factory=dict)  # PIL thumbnails
    # (config, surface, method) -> family -> RADV/ACO's figures of the cell's HLSL program
    # (render.gpu_stats.GpuStats.as_dict), with --gpu-stats
    gpu_stats: dict[tuple[str, str, str], dict[str, dict]] = field(default_factory=dict)

    def config_methods(self, config: BenchConfig) -> list[str]:
        return config.applies_to(self.methods)
