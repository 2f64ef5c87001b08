"""Bad input raises a Python exception that says what is wrong, never a crash."""

import numpy as np
import pytest

import weft

from conftest import run_weft

HANGING = "assets/scenes/hanging.toml"


@pytest.fixture
def sim():
    return weft.Simulation(HANGING)


def test_a_scene_that_does_not_validate_says_file_line_and_key_as_the_cli(tmp_path, weft_bin):
    bad = tmp_path / "bad.toml"
    bad.write_text(
        "[sim]\nsubsteps = 0\n\n[cloth.flag]\nresolution = [8, 8]\nstretch_compliance = -1.0\n"
    )
    with pytest.raises(weft.SceneError) as e:
        weft.Simulation(str(bad))
    cli = run_weft(weft_bin, "check", bad, check=False)
    assert cli.returncode != 0
    lines = [line.removeprefix("error: ") for line in cli.stderr.splitlines() if line.startswith("error: ")]
    assert str(e.value).splitlines() == lines
    assert f"{bad}:2: sim.substeps:" in str(e.value)
    assert f"{bad}:6: cloth.flag.stretch_compliance:" in str(e.value)


def test_an_unknown_override_a_bad_value_or_a_missing_file_is_a_scene_error():
    with pytest.raises(weft.SceneError, match="sim.substep"):
        weft.Simulation(HANGING, overrides={"sim.substep": 20})
    with pytest.raises(weft.SceneError, match="sim.damping"):
        weft.Simulation(HANGING, overrides={"sim.damping": float("nan")})
    with pytest.raises(weft.SceneError, match="method"):
        weft.Simulation(HANGING, method="rk4")
    with pytest.raises(weft.SceneError, match="no/such.toml"):
        weft.Simulation("no/such.toml")
    with pytest.raises(ValueError, match="<string>:2"):
        weft.Simulation("[sim]\nsubsteps = -3\n")
    with pytest.raises(TypeError, match="keys must be strings"):
        weft.Simulation(HANGING, overrides={1: 2})
    with pytest.raises(TypeError, match="override's value"):
        weft.Simulation(HANGING, overrides={"sim.substeps": object()})


def test_live_settings_refuse_unknown_keys_bad_types_and_values_out_of_range(sim):
    with pytest.raises(KeyError, match="not a live setting"):
        sim.set("sim.substep", 20)
    with pytest.raises(KeyError, match="no cloth named `flag`"):
        sim.set("cloth.flag.stretch_compliance", 1e-6)
    with pytest.raises(KeyError, match="when the scene is built"):
        sim.set("cloth.cloth.stretch_enabled", 0)
    with pytest.raises(ValueError, match="finite"):
        sim.set("sim.damping", float("nan"))
    with pytest.raises(ValueError, match="whole number"):
        sim.set("sim.substeps", 2.5)
    with pytest.raises(ValueError, match="invalid"):
        sim.set("cloth.cloth.stretch_compliance", -1.0)
    with pytest.raises(ValueError, match="unknown method"):
        sim.set("sim.method", "rk4")
    with pytest.raises(TypeError, match="bool"):
        sim.set("sim.substeps", True)
    with pytest.raises(TypeError, match="three numbers"):
        sim.set("sim.gravity", [0.0, -9.81])
    sim.step()
    assert sim.frame == 1, "refusals changed nothing that stops it stepping"


def test_an_unknown_cloth_is_a_key_error_everywhere(sim):
    for call in (
        lambda: sim.positions("flag"),
        lambda: sim.velocities("flag"),
        lambda: sim.triangles("flag"),
        lambda: sim.set_positions("flag", np.zeros((1024, 3))),
        lambda: sim.grab("flag", 0, [0.0, 0.0, 0.0]),
    ):
        with pytest.raises(KeyError, match="the scene's cloths are `cloth`"):
            call()


def test_positions_of_the_wrong_shape_dtype_or_value_are_refused(sim):
    before = sim.positions("cloth")
    with pytest.raises(ValueError, match=r"shape \(1024, 3\), got shape \[1023, 3\]"):
        sim.set_positions("cloth", np.zeros((1023, 3)))
    with pytest.raises(ValueError, match="got shape"):
        sim.set_positions("cloth", np.zeros(3072))
    with pytest.raises(TypeError, match="dtype"):
        sim.set_positions("cloth", before.astype(np.float32))
    with pytest.raises(TypeError, match="got list"):
        sim.set_positions("cloth", before.tolist())
    nan = before.copy()
    nan[5, 1] = np.nan
    with pytest.raises(ValueError, match="particle 5"):
        sim.set_positions("cloth", nan)
    inf = before.copy()
    inf[7, 0] = np.inf
    with pytest.raises(ValueError, match="particle 7"):
        sim.set_positions("cloth", inf)
    np.testing.assert_array_equal(sim.positions("cloth"), before)


def test_a_particle_out_of_range_or_a_bad_target_is_refused(sim):
    with pytest.raises(IndexError, match="1024 particles: there is no particle 1024"):
        sim.grab("cloth", 1024, [0.0, 1.0, 0.0])
    with pytest.raises(IndexError, match="index -1 is negative"):
        sim.grab("cloth", -1, [0.0, 1.0, 0.0])
    with pytest.raises(ValueError, match="finite"):
        sim.grab("cloth", 3, [0.0, float("nan"), 0.0])
    with pytest.raises(TypeError, match="three numbers"):
        sim.grab("cloth", 3, [0.0, 1.0])
    with pytest.raises(TypeError, match="three numbers"):
        sim.grab("cloth", 3, "up")
    sim.step()
    free = weft.Simulation(HANGING)
    free.step()
    np.testing.assert_array_equal(sim.positions("cloth"), free.positions("cloth"))


def test_a_divergence_is_a_simulation_error_and_a_negative_count_an_overflow():
    sim = weft.Simulation("assets/scenes/explode.toml")
    with pytest.raises(weft.SimulationError, match="diverged"):
        sim.step(600)
    with pytest.raises(OverflowError):
        weft.Simulation(HANGING).step(-1)


def test_recording_refuses_a_second_log_a_directory_and_the_scene_file(tmp_path, sim):
    with pytest.raises(OSError, match="directory"):
        sim.record(tmp_path)
    with pytest.raises(ValueError, match="scene file"):
        sim.record(HANGING)
    sim.record(tmp_path / "a.mcap")
    with pytest.raises(RuntimeError, match="already recording"):
        sim.record(tmp_path / "b.mcap")
    assert sim.stop_recording() == tmp_path / "a.mcap"
    assert sim.stop_recording() is None
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.mcap"]
