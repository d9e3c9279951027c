"""Design from Python: a small PR-SSM trained on 48 of the paper's trajectories, a hover
design verified on the wing, the closed loop, and bad targets refused by name."""

import pytest

import flapssm


@pytest.fixture(scope="module")
def model(tmp_path_factory):
    angles = flapssm.paper_angles()[:48]
    ds = flapssm.simulate_angles(angles, n_train=40, seed=1)
    path = tmp_path_factory.mktemp("design") / "prssm.json"
    flapssm.train(ds, path, preset="paper-fast", dx=6, inducing=16, particles=6, epochs=30, seed=1)
    return path


def test_hover_returns_verified_designs(model, tmp_path):
    seen = []
    r = flapssm.design_hover(
        model, 0.1, out=tmp_path, iterations=30, starts=2, particles=8,
        progress=lambda stage, done, total: seen.append(stage),
    )
    assert [d["design"]["model"] for d in r["designs"]] == ["prssm", "quasi-steady"]
    lift = flapssm.STROKE_QUANTITIES.index("lift_n")
    for d in r["designs"]:
        assert abs(d["design"]["evaluation"]["cycle_means"][lift] - 0.1) < 0.01
        assert len(d["achieved"]) == 7
    assert r["designs"][0]["design"]["cycle_mean_sd"] is not None
    assert (tmp_path / "design.json").exists() and (tmp_path / "design.md").exists()
    assert seen


def test_bad_targets_name_the_field(model):
    with pytest.raises(ValueError, match="target.lift_n.*unreachable"):
        flapssm.design_target(model, {"lift_n": 40.0}, iterations=2, starts=1)
    with pytest.raises(ValueError, match="unknown quantities"):
        flapssm.design_target(model, {"lift": 0.1})
    with pytest.raises(ValueError, match="weight_n"):
        flapssm.design_hover(model, float("nan"))
    with pytest.raises(TypeError, match="unknown design settings"):
        flapssm.design_hover(model, 0.1, iteration=3)
    with pytest.raises(FileNotFoundError):
        flapssm.design_hover("no-such-model.json", 0.1)


def test_closed_loop_record(model):
    r = flapssm.design_control(model, 0.1, density_factor=1.2, cycles=3, particles=8)
    assert [c["cycle"] for c in r["cycles"]] == [1, 2, 3]
    assert r["settings"]["density_factor"] == 1.2
