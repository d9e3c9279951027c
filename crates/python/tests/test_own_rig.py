"""A user's own rig from Python: the description, a rehearsal, the build back to the wing's loads
(from CSV and from MATLAB v7.3), and arrays that take the rig's geometry (docs/own-rig.md)."""
import json

import h5py
import numpy as np
import pytest

import flapssm


@pytest.fixture(scope="module")
def rig(tmp_path_factory):
    path = tmp_path_factory.mktemp("rig") / "rig.toml"
    path.write_text(flapssm.rig_template())
    return path


@pytest.fixture(scope="module")
def rehearsal(rig, tmp_path_factory):
    raw = tmp_path_factory.mktemp("raw")
    truth = flapssm.rehearse_rig(rig, raw, n=2, seed=4, motion_s=10.0)
    return raw, truth


def test_the_template_is_a_checked_description(rig):
    desc = flapssm.load_rig(rig)
    assert desc["wing"]["span_m"] == 0.12 and desc["fluid"]["density_kg_m3"] == 1000.0
    assert desc["angles"]["order"] == ["stroke", "pitch", "deviation"]
    # The same description as a dict; a field out of range is refused by name.
    assert flapssm.load_rig(desc) == desc
    bad = json.loads(json.dumps(desc))
    bad["filter"]["cutoff_hz"] = 80.0
    with pytest.raises(ValueError, match="filter.cutoff_hz"):
        flapssm.load_rig(bad)
    bad = json.loads(json.dumps(desc))
    bad["sensor"]["spin"] = 1
    with pytest.raises(ValueError, match="unknown field `spin`"):
        flapssm.load_rig(bad)


def test_a_rehearsed_rig_builds_back_to_the_wings_loads(rig, rehearsal, tmp_path):
    raw, truth = rehearsal
    files = sorted(raw.glob("recording_*.csv"))
    steps = tmp_path / "steps"
    seen = []
    ds = flapssm.build_dataset(rig, files, steps=steps, progress=lambda *a: seen.append(a))
    assert seen and (steps / "recording_000.steps.png").is_file()
    assert ds.outputs.shape == truth.outputs.shape and ds.dt_s == 0.04
    for got, want in zip(ds.outputs, truth.outputs):
        rms = np.sqrt(np.mean(want ** 2, axis=0))
        scale = np.r_[[rms[:2].max()] * 2, [rms[2:].max()] * 3]
        err = np.sqrt(np.mean((got - want) ** 2, axis=0)) / scale
        assert np.all(err < 0.01), err
    meta = json.loads(ds.metadata_json)
    assert meta["wing"]["chord_m"] == 0.04 and meta["fluid"]["density_kg_m3"] == 1000.0
    reports = meta["settings"]["recordings"]
    assert len(reports) == 2 and all(max(r["rest_residual"]) < 0.02 for r in reports)


def _to_v73(csv, mat):
    """The recording as MATLAB -v7.3 saves it: one double column vector per channel (stored
    transposed, with MATLAB_class), behind the 512-byte MAT header."""
    names = csv.read_text().splitlines()[0].split(",")
    data = np.loadtxt(csv, delimiter=",", skiprows=1)
    with h5py.File(mat, "w", userblock_size=512) as f:
        for k, name in enumerate(names):
            d = f.create_dataset(name, data=data[:, k][None, :], chunks=(1, 4096), compression="gzip")
            d.attrs["MATLAB_class"] = np.bytes_("double")
    header = b"MATLAB 7.3 MAT-file, Platform: GLNXA64, Created on: test HDF5 schema 1.00 ."
    with open(mat, "r+b") as fh:
        fh.write(header.ljust(116, b" ") + b"\x00" * 8 + b"\x00\x02" + b"IM")


def test_a_matlab_v73_recording_builds_as_its_csv(rig, rehearsal, tmp_path):
    raw, _ = rehearsal
    csv = raw / "recording_000.csv"
    mat = tmp_path / "recording_000.mat"
    _to_v73(csv, mat)
    from_csv = flapssm.build_dataset(rig, [csv], n_train=1)
    from_mat = flapssm.build_dataset(rig, [mat], n_train=1)
    assert np.array_equal(from_csv.outputs, from_mat.outputs)
    assert np.array_equal(from_csv.euler_rad, from_mat.euler_rad)


def test_arrays_take_the_rigs_geometry(rig, rehearsal):
    _, truth = rehearsal
    ds = flapssm.dataset_from_arrays(truth.euler_rad, truth.inputs, truth.outputs, dt_s=truth.dt_s,
                                     rig=rig)
    meta = json.loads(ds.metadata_json)
    assert meta["wing"]["span_m"] == 0.12
    # U_ref at the rig's radius (the tip, 0.15 m): the truth's own.
    assert np.allclose(ds.u_ref_m_s, truth.u_ref_m_s, rtol=1e-12)
    paper = flapssm.dataset_from_arrays(truth.euler_rad, truth.inputs, truth.outputs, dt_s=truth.dt_s,
                                        rig="paper")
    assert np.allclose(paper.u_ref_m_s / ds.u_ref_m_s, 0.235 / 0.15, rtol=1e-9)
    with pytest.raises(TypeError, match="rig"):
        flapssm.dataset_from_arrays(truth.euler_rad, truth.inputs, rig=3)
