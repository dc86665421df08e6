"""Constrained layouts kept between runs (runtime/results/layout_memo.py): a figure laid out from the memo is the
figure matplotlib lays out, byte for byte; what changes its texts, limits or style is laid out again."""

from __future__ import annotations

import dataclasses
import io

import matplotlib
import pytest

import apexseal
from apexseal.runtime.results import layout_memo
from apexseal.runtime.results.figures import ports_of
from apexseal.runtime.results.plots import figure
from apexseal.runtime.results.saved_figures import figure_files


@pytest.fixture(scope="module")
def result(default_scene, default_functions):
    return apexseal.simulate(default_scene, revolutions=2, samples_per_revolution=360, flags="quick", rtol=1e-8,
                             functions=default_functions.sx)


@pytest.fixture
def memo(tmp_path, monkeypatch):
    """A private, empty memo."""
    monkeypatch.setenv("APEXSEAL_CACHE", str(tmp_path / "cache"))
    monkeypatch.delenv("APEXSEAL_LAYOUT_MEMO", raising=False)
    return tmp_path / "cache" / "layouts"


def _png(fig, memo: bool = True) -> tuple[bytes, bool | None]:
    """The PNG bytes of ``fig`` saved as a run saves it (through the memo, or not) and whether the memo had it."""
    out = io.BytesIO()
    kept = (layout_memo.savefig(fig, out, dpi=100, format="png") if memo else
            fig.savefig(out, dpi=100, format="png"))
    return out.getvalue(), kept


def kept_layouts_draw_the_same(result, ports) -> None:
    """Each figure of ``result``: laid out by matplotlib, then from the memo (which the first save filled), the
    same PNG bytes (also the check of the gas figures, tests/runtime/test_gas.py)."""
    for kind in figure_files(result).values():
        fresh, _ = _png(figure(result, kind, ports=ports, save_dpi=100), memo=False)
        first, kept_first = _png(figure(result, kind, ports=ports, save_dpi=100))
        again, kept_again = _png(figure(result, kind, ports=ports, save_dpi=100))
        assert (kept_first, kept_again) == (False, True), kind
        assert fresh == first == again, kind


def test_a_kept_layout_draws_the_same_png(result, default_scene, memo):
    kept_layouts_draw_the_same(result, ports_of(default_scene))
    assert len(list(memo.glob("*.json"))) == len(figure_files(result))


def test_other_tick_labels_are_laid_out_again(result, default_scene, memo):
    """Forces ten times larger change Fig. 13's value ticks: a new signature, laid out by matplotlib (the same
    bytes as without the memo), and kept beside the first."""
    _png(figure(result, "fig13", save_dpi=100))
    louder = dataclasses.replace(result, outputs={k: 10 * v if k.startswith("F_") else v
                                                  for k, v in result.outputs.items()})
    fresh, _ = _png(figure(louder, "fig13", save_dpi=100), memo=False)
    drawn, kept = _png(figure(louder, "fig13", save_dpi=100))
    assert kept is False and drawn == fresh
    assert len(list(memo.glob("*.json"))) == 2


def test_the_signature_follows_texts_style_and_resolution(result):
    base = layout_memo.signature(figure(result, "fig14", save_dpi=100), 100)
    assert layout_memo.signature(figure(result, "fig14", save_dpi=100), 100) == base
    assert layout_memo.signature(figure(result, "fig14", save_dpi=100), 150) != base
    relabelled = figure(result, "fig14", save_dpi=100)
    relabelled.axes[0].set_xlabel("another label")
    assert layout_memo.signature(relabelled, 100) != base
    with matplotlib.rc_context({"font.size": 14}):
        assert layout_memo.signature(figure(result, "fig14", save_dpi=100), 100) != base


def test_a_broken_or_foreign_memo_is_laid_out_as_without_it(result, memo):
    fig = figure(result, "modes", save_dpi=100)
    key = layout_memo.signature(fig, 100)
    fresh, _ = _png(figure(result, "modes", save_dpi=100), memo=False)
    memo.mkdir(parents=True)
    for text in ("{not json", '{"axes": [[[[0, 0], [1, 1]], [[0, 0], [1, 1]]]], "suptitle": null}'):  # 1 axes of 2
        (memo / f"{key}.json").write_text(text)
        drawn, kept = _png(figure(result, "modes", save_dpi=100))
        assert kept is False and drawn == fresh


def test_the_memo_can_be_turned_off(result, memo, monkeypatch):
    monkeypatch.setenv("APEXSEAL_LAYOUT_MEMO", "0")
    assert [_png(figure(result, "fig14", save_dpi=100))[1] for _ in range(2)] == [False, False]
    assert not memo.exists()


def test_the_memo_keeps_at_most_its_limit(result, memo, monkeypatch):
    monkeypatch.setattr(layout_memo, "LIMIT", 2)
    for scale in (1, 10, 100):
        louder = dataclasses.replace(result, outputs={k: scale * v for k, v in result.outputs.items()})
        _png(figure(louder, "fig13", save_dpi=100))
    assert len(list(memo.glob("*.json"))) == 2


def test_the_signature_is_the_same_in_every_process_and_leaves_the_backend_alone():
    """A new process computes the signature of the same figure as another one did (the memo serves the next run),
    and reading the rcParams for it neither imports pyplot nor resolves the backend (figures never touch the
    user's backend)."""
    import subprocess
    import sys

    code = ("import sys, matplotlib; from matplotlib.figure import Figure; "
            "from apexseal.runtime.results import layout_memo; "
            "fig = Figure(layout='constrained'); fig.subplots().set_title('t'); "
            "print(layout_memo.signature(fig, 100), 'matplotlib.pyplot' in sys.modules)")
    runs = [subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout.split()
            for _ in range(2)]
    assert runs[0] == runs[1] and runs[0][1] == "False"
