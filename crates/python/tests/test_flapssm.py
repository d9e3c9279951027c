"""The Python package against the CLI, the files and itself."""

import json
import os
import signal

import numpy as np
import pytest

import flapssm
from conftest import SHARED


@pytest.fixture(scope="module")
def small():
    return flapssm.simulate(4, seed=3, fidelity="l0", n_train=3)


def test_dataset_round_trips_through_files_and_arrays(small, tmp_path):
    path = tmp_path / "wing.npz"
    small.save(path)
    back = flapssm.Dataset.load(path)
    for name in ["euler_rad", "inputs", "outputs", "u_ref_m_s"]:
        assert np.array_equal(getattr(back, name), getattr(small, name)), name
    assert (len(back), back.n_samples, back.n_train, back.dt_s) == (4, 470, 3, 0.04)
    assert small.inputs.shape == (4, 470, 7) and small.inputs.dtype == np.float64

    made = flapssm.dataset_from_arrays(small.euler_rad, small.inputs, small.outputs, n_train=3,
                                       u_ref_m_s=small.u_ref_m_s, rig="paper")
    made.save(tmp_path / "made.npz")
    again = flapssm.Dataset.load(tmp_path / "made.npz")
    assert np.array_equal(again.outputs, small.outputs)
    # U_ref by the published rule when not given: the simulator's own value.
    with pytest.warns(UserWarning, match="the paper's wing is assumed"):
        derived = flapssm.dataset_from_arrays(small.euler_rad, small.inputs, small.outputs)
    assert np.allclose(derived.u_ref_m_s, small.u_ref_m_s, rtol=1e-12)


def test_simulation_equals_the_cli(cli, small, tmp_path):
    out = tmp_path / "cli.npz"
    cli("simulate", "--n", 4, "--n-train", 3, "--seed", 3, "--fidelity", "l0", "--quiet", "--out", out)
    from_cli = flapssm.Dataset.load(out)
    for name in ["euler_rad", "inputs", "outputs", "u_ref_m_s"]:
        assert np.array_equal(getattr(from_cli, name), getattr(small, name)), name


def test_prediction_equals_the_cli_and_the_stream(cli, published, tmp_path):
    model = flapssm.PRSSM.import_published(published)
    u = np.load(published)["u_in"]
    csv = tmp_path / "u.csv"
    np.savetxt(csv, u, delimiter=",", header=",".join(flapssm.INPUT_NAMES), comments="", fmt="%.17g")
    model.save(tmp_path / "m.json")
    cli("predict", tmp_path / "m.json", "--inputs", csv, "--seed", 5, "--out", tmp_path / "p.csv")
    table = np.loadtxt(tmp_path / "p.csv", delimiter=",", skiprows=1)
    mean, var, latent, none = model.predict_inputs(u, particles=30, seed=5)
    assert mean.shape == (470, 5) and latent.shape == (470, 12) and none is None
    m2, v2, l2, particles = model.predict_inputs(u, particles=30, seed=5, return_particles=True)
    assert particles.shape == (470, 30, 12)
    assert np.array_equal(m2, mean) and np.array_equal(v2, var) and np.array_equal(l2, latent)
    assert np.allclose(particles.mean(axis=1), latent, rtol=1e-12, atol=1e-12)
    assert np.allclose(table[:, 1:6], mean, rtol=1e-15, atol=0)
    assert np.allclose(table[:, 6:11], var, rtol=1e-15, atol=0)

    stream = model.stream(particles=30, seed=5)
    for t in range(470):
        m, v = stream.step(u[t])
        assert np.array_equal(m, mean[t]) and np.array_equal(v, var[t]), t
    stream.reset()
    m0, _ = stream.step(u[0])
    assert np.array_equal(m0, mean[0])
    with pytest.raises(ValueError, match="expected 7"):
        stream.step(u[0, :6].copy())


def test_bad_input_raises_the_right_exception(small, tmp_path):
    with pytest.raises(FileNotFoundError, match="missing.npz"):
        flapssm.Dataset.load(tmp_path / "missing.npz")
    with pytest.raises(FileNotFoundError):
        flapssm.PRSSM.load(tmp_path / "missing.json")
    garbage = tmp_path / "garbage.npz"
    garbage.write_text("not a dataset")
    with pytest.raises(ValueError, match="garbage.npz"):
        flapssm.Dataset.load(garbage)
    with pytest.raises(ValueError, match=r"inputs: shape \(4, 470, 6\), expected \(4, 470, 7\)"):
        flapssm.dataset_from_arrays(small.euler_rad, small.inputs[:, :, :6], rig="paper")
    with pytest.raises(TypeError, match="dtype"):
        flapssm.dataset_from_arrays(small.euler_rad.astype(str), small.inputs, rig="paper")
    nan = small.inputs.copy()
    nan[1, 7, 2] = np.nan
    with pytest.raises(ValueError, match=r"non-finite value at index \(1, 7, 2\)"):
        flapssm.dataset_from_arrays(small.euler_rad, nan, rig="paper")
    with pytest.raises(ValueError, match="fidelity"):
        flapssm.simulate(2, fidelity="l9")
    with pytest.raises(ValueError, match="n_train"):
        flapssm.simulate(2, n_train=5)
    with pytest.raises(ValueError, match="preset"):
        flapssm.train(small, tmp_path / "m.json", preset="fast")
    with pytest.raises(ValueError, match="best_by"):
        flapssm.train(small, tmp_path / "m.json", best_by="lowest")
    with pytest.raises(ValueError, match="objective"):
        flapssm.train(small, tmp_path / "m.json", objective="tf1")
    with pytest.raises(ValueError, match="inducing_init"):
        flapssm.train(small, tmp_path / "m.json", inducing_init="grid")
    with pytest.raises(ValueError, match="precision"):
        flapssm.train(small, tmp_path / "m.json", precision="f16")
    with pytest.raises(ValueError, match="lengthscale_init"):
        flapssm.train(small, tmp_path / "m.json", lengthscale_init=-1.0)
    with pytest.raises(ValueError, match="windows_per_task"):
        flapssm.train(small, tmp_path / "m.json", windows_per_task=0)
    with pytest.raises(ValueError, match="unknown schedule"):
        flapssm.train(small, tmp_path / "m.json", schedule="linear")
    with pytest.raises(ValueError, match="dx"):
        flapssm.train(small, tmp_path / "m.json", dx=2.5)
    with pytest.raises(OSError, match="is a directory"):
        small.save(tmp_path)


def _tiny(small, out, **kw):
    return flapssm.train(small, out, "sysid", dx=5, inducing=8, particles=4, batch=2, epochs=6,
                         checkpoint_every=0, seed=2, **kw)


def test_keyboard_interrupt_leaves_a_resumable_checkpoint(small, tmp_path, sigint_raises):
    whole = _tiny(small, tmp_path / "whole.json")
    calls = []

    def interrupt(stage, position, total):
        calls.append(position)
        if position == 3 and total > 0:
            signal.raise_signal(signal.SIGINT)

    out = tmp_path / "m.json"
    with pytest.raises(KeyboardInterrupt, match="resume"):
        _tiny(small, out, progress=interrupt)
    assert (tmp_path / "m.ckpt.json").exists() and not out.exists()
    assert not [f for f in os.listdir(tmp_path) if f.endswith(".tmp")]
    resumed = _tiny(small, out, resume=True)
    assert resumed.to_json() == whole.to_json()
    assert len(calls) > 3
    # The learning curve: one row per evaluated epoch, continued across the interruption.
    rows = (tmp_path / "m.curve.csv").read_text().splitlines()
    assert rows[1] == "epoch,step,wall_s,mean_loss,train_rmse,val_rmse"
    assert [int(r.split(",")[0]) for r in rows[2:]] == list(range(6))


def test_start_precision_and_task_size_are_recorded(small, tmp_path):
    model = _tiny(small, tmp_path / "k.json", inducing_init="kmeans", precision="mixed",
                  windows_per_task=1, lengthscale_init=5.0)
    spec = json.loads(model.to_json())["model"]["training"]["spec"]
    assert spec["inducing_init"] == "kmeans" and spec["precision"] == "mixed"
    assert spec["windows_per_task"] == 1 and spec["init"]["lengthscale"] == 5.0


def test_ctrl_c_from_outside_stops_training_with_a_checkpoint(small, tmp_path, sigint_raises):
    # SIGINT from another thread while the main thread is inside the Rust training loop
    # (no callback): the loop's own check of Python's signals stops it.
    import threading

    out = tmp_path / "m.json"
    timer = threading.Timer(0.3, lambda: os.kill(os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt, match="resume"):
            flapssm.train(small, out, "sysid", dx=5, inducing=8, particles=4, batch=2,
                          epochs=100_000, checkpoint_every=0, seed=2)
    finally:
        timer.cancel()
    checkpoint = json.loads((tmp_path / "m.ckpt.json").read_text())
    assert checkpoint["state"]["step"] > 0
    assert not [f for f in os.listdir(tmp_path) if f.endswith(".tmp")]


def test_estimators_follow_scikit_learn_conventions(small):
    est = flapssm.LRQSMRegressor(n_folds=3)
    assert est.get_params()["n_folds"] == 3
    assert est.set_params(n_folds=4) is est and est.n_folds == 4
    with pytest.raises(ValueError, match="[Ii]nvalid parameter"):
        est.set_params(bogus=1)
    with pytest.raises(ValueError, match="not fitted"):
        est.predict(small)
    # Arrays: the motion (Euler angles) and the loads; the inputs come from the angles.
    est.fit(small.euler_rad, small.outputs)
    assert est.coef_.shape == (5, 11) and est.lambda_.shape == (5,)
    pred = est.predict(small.euler_rad)
    u = np.stack([flapssm.kinematics(e, 0.04) for e in small.euler_rad])
    same = flapssm.dataset_from_arrays(small.euler_rad, u, small.outputs, rig="paper")
    assert np.array_equal(pred, flapssm.LRQSM.fit(same, n_folds=4).predict(same))
    with pytest.raises(ValueError, match=r"X: Euler angles \(n_trajectories, n_samples, 3\)"):
        est.predict(small.inputs)
    with pytest.raises(ValueError, match="requires y"):
        flapssm.LRQSMRegressor().fit(small.euler_rad)
    clone = type(est)(**est.get_params())
    assert not hasattr(clone, "model_") and clone.get_params() == est.get_params()
    # A Dataset as X carries its own inputs and loads.
    prssm = flapssm.PRSSMRegressor(preset="sysid", dx=5, inducing=8, particles=4, batch=2, epochs=2,
                                   predict_particles=5)
    mean, std = prssm.fit(small).predict(small, return_std=True)
    assert mean.shape == (4, 470, 5) and (std > 0).all() and prssm.n_state_ == 5


def test_train_keywords_are_the_training_options():
    """One schema: the training keywords of ``flapssm.train`` are ``TRAINING_OPTIONS`` (the
    ``flapssm train`` flags), besides the dataset, the files and the callback."""
    import inspect

    keywords = set(inspect.signature(flapssm.train).parameters)
    assert keywords - {"dataset", "out", "resume", "progress"} == set(flapssm.TRAINING_OPTIONS)
    assert "schedule" in flapssm.TRAINING_OPTIONS and "eval_every" in flapssm.TRAINING_OPTIONS


def test_train_in_memory_writes_nothing(small, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    model = flapssm.train(small, None, "sysid", dx=5, inducing=8, particles=4, batch=2, epochs=2)
    assert model.n_state == 5 and list(tmp_path.iterdir()) == []
    same = flapssm.train(small, tmp_path / "m.json", "sysid", dx=5, inducing=8, particles=4, batch=2, epochs=2)
    a, b = (m.predict_dataset(small, 5, 1)[0] for m in (model, same))
    assert np.array_equal(a, b), "in memory and through files: the same model"
    with pytest.raises(ValueError, match="resume"):
        flapssm.train(small, None, "sysid", resume=True)


def test_evaluate_returns_the_metrics(small, tmp_path):
    lrqsm = flapssm.LRQSM.fit(small, n_folds=3)
    model = _tiny(small, tmp_path / "m.json")
    report = flapssm.evaluate(small, tmp_path / "eval", prssm=model, lrqsm=lrqsm, particles=5,
                              baselines=["gp-static"])
    names = [m["model"] for m in report["models"]]
    assert names == ["PR-SSM", "LRQSM", "GP-static"]
    # The PR-SSM against each other model: a paired interval per output around the difference.
    pairs = report["comparisons"]
    assert [(c["a"], c["b"]) for c in pairs] == [("prssm", "lrqsm"), ("prssm", "gp-static")]
    for c in pairs:
        assert len(c["outputs"]) == 5
        for d in c["outputs"]:
            assert d["interval"]["lo"] <= d["difference"] <= d["interval"]["hi"]
            assert d["significant"] == (d["interval"]["lo"] > 0 or d["interval"]["hi"] < 0)
    # The dict is metrics.json, written in the folder.
    assert json.loads((tmp_path / "eval" / "metrics.json").read_text()) == report
    # Control authority of the PR-SSM's 5 latent states over the 7 inputs.
    findings = report["authority_findings"]
    labels = {"AoA", "|v|", "a_x", "a_y", "a_z", "dα/dt", "d²α/dt²"}
    assert findings and {f["input"] for f in findings} <= labels
    assert {f["state"] for f in findings} <= {f"x{i}" for i in range(1, 6)}
    assert all(0.0 <= f["median_abs_r"] <= 1.0 for f in findings)
    # D_x 5: every state is an output, so there is no hidden subspace to analyse.
    assert report["hidden_authority"] == []
    # The paper beside this evaluation, each row with its source in the paper.
    rows = report["paper_comparison"]
    assert any(r["endpoint"].startswith("C_Fx RMSE, PR-SSM") for r in rows)
    assert all(r["source"] and r["paper"] and r["flapssm"] for r in rows)


def test_history_curve_writes_its_files_and_refuses_bad_cycles(small, tmp_path):
    curves = flapssm.history_curve({"small": small}, tmp_path / "h", cycles=[0.0, 0.25])
    (c,) = curves["curves"]
    assert c["dataset"] == "small" and [r["history_cycles"] for r in c["rows"]] == [0.0, 0.25]
    assert c["rows"][0]["versus_static"] == [] and len(c["rows"][1]["versus_static"]) == 5
    assert json.loads((tmp_path / "h" / "history_curve.json").read_text()) == curves
    assert (tmp_path / "h" / "history_curve.png").stat().st_size > 0
    with pytest.raises(ValueError, match="history_cycles"):
        flapssm.history_curve({"small": small}, tmp_path / "h2", cycles=[0.5, 0.25])
    assert not (tmp_path / "h2").exists()


def test_trajectories_kinematics_and_sysid_equal_the_cli(cli, tmp_path):
    ds = flapssm.trajectories(3, seed=4)
    assert ds.outputs is None
    cli("trajectories", "--n", 3, "--seed", 4, "--out", tmp_path / "t.npz")
    from_cli = flapssm.Dataset.load(tmp_path / "t.npz")
    assert np.array_equal(from_cli.inputs, ds.inputs) and np.array_equal(from_cli.euler_rad, ds.euler_rad)

    # The generator's inputs are analytic: the differentiated angles give them back.
    u = flapssm.kinematics(ds.euler_rad[0], ds.dt_s)
    assert u.shape == (470, 7)
    scale = np.abs(ds.inputs[0]).max(axis=0)
    interior = slice(10, -10)
    err = np.abs(u[interior] - ds.inputs[0][interior]).max(axis=0) / scale
    assert (err < 0.02).all(), err
    with pytest.raises(ValueError, match="shape"):
        flapssm.kinematics(ds.euler_rad[0][:, :2], ds.dt_s)

    ballbeam = SHARED / "data" / "sysid" / "ballbeam.csv"
    args = dict(split=0.5, seeds=1, restarts=1, iterations=5)
    seen = []
    report = flapssm.sysid(ballbeam, ["u"], ["y"], progress=lambda s, r: seen.append((s, r)), **args)
    out = cli("sysid", ballbeam, "--input", "u", "--output", "y", "--seeds", 1, "--restarts", 1,
              "--iterations", 5, "--json").stdout
    from_cli = json.loads(out)
    assert report["rmse"] == from_cli["rmse"] and report["nll"] == from_cli["nll"]
    assert seen == [(0, report["runs"][0]["test"]["rmse"])]
    with pytest.raises(FileNotFoundError):
        flapssm.sysid(tmp_path / "missing.csv", ["u"], ["y"], **args)
    with pytest.raises(ValueError, match="combine"):
        flapssm.sysid(ballbeam, ["u"], ["y"], combine="vote", **args)


def test_lrqsm_cv_path_as_arrays(small):
    m = flapssm.LRQSM.fit(small, n_folds=3)
    path = m.cv_path(1)
    n = path["lambdas"].shape[0]
    assert path["coef_path"].shape == (n, 11) and path["cv_mse_mean"].shape == (n,)
    assert np.array_equal(path["coef_path"][path["index_chosen"]], m.coef_[1])
    assert path["lambdas"][path["index_chosen"]] == m.lambda_[1]
    with pytest.raises(ValueError, match="5 outputs"):
        m.cv_path(5)


def test_simulation_on_the_papers_measured_trajectories():
    euler = flapssm.paper_angles(3)
    # The vendored set is the shared one, deviation and pitch negated (docs/kinematics.md).
    shared = np.load(SHARED / "data" / "bayiz2021-kinematics" / "euler_angles.npy")[:3]
    assert np.array_equal(euler, shared * np.array([1.0, -1.0, -1.0]))
    assert flapssm.paper_angles().shape == (548, 470, 3)
    with pytest.raises(ValueError, match="at most the paper's 548"):
        flapssm.paper_angles(549)
    ds = flapssm.simulate_angles(euler, seed=2, fidelity="l1", n_train=2)
    assert (len(ds), ds.n_train, ds.n_samples) == (3, 2, 470)
    assert ds.families == ["measured"] * 3 and np.isfinite(ds.outputs).all()
    # Past the 2 s ramp-in from rest at the first measured pose: the measured angles, smoothed.
    assert np.abs(ds.euler_rad[:, 50:] - euler[:, 50:]).max() < np.radians(1)
    assert np.abs(ds.euler_rad[:, 0] - euler[:, 0]).max() < np.radians(1)
    again = flapssm.simulate_angles(euler, seed=2, fidelity="l1", n_train=2)
    assert np.array_equal(again.outputs, ds.outputs)  # same seed, same dataset
    with pytest.raises(ValueError, match=r"expected \(n, 470, 3\)"):
        flapssm.simulate_angles(euler[:, :400])


def test_rig_check_and_wing_settings_equal_the_cli(cli, published, tmp_path):
    euler = flapssm.paper_angles(6)
    wing = {"fidelity": "l0", "mount": {"plate_pitch_deg": 4.0}}
    ds = flapssm.simulate_angles(euler, fidelity="l0", wing=wing, noise_free=True)
    ds.save(tmp_path / "d.npz")
    cli("simulate", "--source", "paper", "--n", 6, "--noise-free", "--fidelity", "l0",
        "--wing-config", _write_json(tmp_path / "w.json", wing), "--out", tmp_path / "c.npz")
    assert np.array_equal(flapssm.Dataset.load(tmp_path / "c.npz").outputs, ds.outputs)
    check = flapssm.rig_check(ds, published, out=tmp_path / "rig", lags=False)
    r = [c["r"] for c in check["train"]["channels"]]
    assert r[0] > 0.95 and r[3] > 0.95, r
    assert check["test"] is None and check["train"]["lags"] == []
    cli("rig", "check", tmp_path / "d.npz", "--reference", published, "--out", tmp_path / "cli", "--no-lags")
    on_disk = json.loads((tmp_path / "cli" / "rig-check.json").read_text())
    assert on_disk["train"]["channels"] == check["train"]["channels"]
    assert (tmp_path / "rig" / "rig-check.md").exists()
    with pytest.raises(ValueError, match="mount.plate_pich_deg"):
        flapssm.simulate_angles(euler, wing={"mount": {"plate_pich_deg": 4.0}})
    with pytest.raises(ValueError, match="--source paper"):
        flapssm.rig_check(flapssm.simulate(3, seed=1, fidelity="l0"), published)
    with pytest.raises(FileNotFoundError):
        flapssm.rig_check(ds, tmp_path / "missing.npz")


def _write_json(path, value):
    path.write_text(json.dumps(value))
    return path
