"""The Python API: loading, stepping, arrays, grabs, statistics and live settings."""

import threading
import time

import numpy as np
import pytest

import weft

HANGING = "assets/scenes/hanging.toml"

SMALL = """
[sim]
dt = "1/60"
substeps = 10
gravity = [0.0, 0.0, 0.0]

[cloth.a]
resolution = [5, 5]
size = [1.0, 1.0]
center = [0.0, 1.5, 0.0]
mass = 0.25
pins = ["top"]
"""


def test_the_module_says_its_version_methods_and_materials():
    assert weft.__version__ == "0.1.0"
    assert weft.methods() == ["xpbd", "pbd", "mass-spring", "implicit-mass-spring"]
    assert "cotton" in weft.materials() and "denim" in weft.materials()
    assert issubclass(weft.SceneError, ValueError)
    assert issubclass(weft.SimulationError, RuntimeError)


def test_a_scene_file_steps_and_its_arrays_have_their_shapes():
    sim = weft.Simulation(HANGING)
    assert sim.cloths == ["cloth"]
    assert (sim.frame, sim.time) == (0, 0.0)
    x0 = sim.positions("cloth")
    assert x0.shape == (1024, 3) and x0.dtype == np.float64
    tris = sim.triangles("cloth")
    assert tris.dtype == np.uint32 and tris.shape == (2 * 31 * 31, 3)
    assert tris.max() == 1023
    sim.step(30)
    assert sim.frame == 30
    assert sim.time == 30 * (1 / 60)
    x = sim.positions("cloth")
    v = sim.velocities("cloth")
    assert v.shape == (1024, 3) and v.dtype == np.float64
    assert x[:, 1].min() < x0[:, 1].min(), "it hangs lower"
    assert np.abs(v).max() > 0.0
    x[:] = 0.0
    assert sim.positions("cloth")[:, 1].min() > 0.5, "arrays are copies"


def test_a_toml_string_is_a_scene_and_overrides_and_method_apply():
    a = weft.Simulation(SMALL.replace("substeps = 10", "substeps = 20"), method="pbd")
    b = weft.Simulation(SMALL, overrides={"sim.substeps": 20, "sim.method": "pbd"})
    c = weft.Simulation(SMALL, overrides={"sim.substeps": 20}, method="pbd")
    for s in (a, b, c):
        s.set("sim.gravity", [0.0, -9.81, 0.0])
        s.step(20)
    np.testing.assert_array_equal(a.positions("a"), b.positions("a"))
    np.testing.assert_array_equal(a.positions("a"), c.positions("a"))
    d = weft.Simulation(SMALL, overrides={"sim.substeps": 20})
    d.set("sim.gravity", [0.0, -9.81, 0.0])
    d.step(20)
    assert not np.array_equal(a.positions("a"), d.positions("a")), "PBD differs from XPBD"


def test_stepping_in_one_call_or_frame_by_frame_gives_the_same_bits():
    a = weft.Simulation(HANGING)
    b = weft.Simulation(HANGING)
    a.step(25)
    for _ in range(25):
        b.step()
    np.testing.assert_array_equal(a.positions("cloth"), b.positions("cloth"))
    np.testing.assert_array_equal(a.velocities("cloth"), b.velocities("cloth"))


def test_live_settings_equal_the_same_values_given_at_load():
    cases = [
        [("sim.substeps", 20)],
        [("sim.iterations", 3)],
        [("sim.method", "pbd")],
        [("sim.method", "pbd"), ("cloth.cloth.shear_pbd_stiffness", 0.3)],
        [("sim.damping", 0.5)],
        [("sim.gravity", (0.0, -3.0, 1.0))],
        [("cloth.cloth.stretch_compliance", 1e-4)],
        [("cloth.cloth.bend_distance_compliance", 0.1)],
        [("wind.velocity", np.array([2.0, 0.0, 1.0])), ("wind.drag", 0.5)],
    ]
    plain = weft.Simulation(HANGING)
    plain.step(20)
    for case in cases:
        overrides = {k: (list(v) if not isinstance(v, (str, int, float)) else v) for k, v in case}
        loaded = weft.Simulation(HANGING, overrides=overrides)
        live = weft.Simulation(HANGING)
        for key, value in case:
            live.set(key, value)
        loaded.step(20)
        live.step(20)
        np.testing.assert_array_equal(live.positions("cloth"), loaded.positions("cloth"), case)
        assert not np.array_equal(live.positions("cloth"), plain.positions("cloth")), case


def test_a_new_time_step_counts_in_time():
    sim = weft.Simulation(SMALL)
    sim.step(3)
    sim.set("sim.dt", "1/120")
    assert sim.dt == 1 / 120
    sim.step(2)
    assert sim.time == pytest.approx(3 / 60 + 2 / 120, abs=1e-12)


def test_set_positions_moves_the_cloth_and_keeps_its_velocities():
    sim = weft.Simulation(SMALL)
    x = sim.positions("a") + np.array([0.0, 0.0, 1.0])
    sim.set_positions("a", x)
    np.testing.assert_array_equal(sim.positions("a"), x)
    # A view with strides (every column of a wider array) is read as it is.
    wide = np.zeros((25, 6))
    wide[:, ::2] = x
    sim.set_positions("a", wide[:, ::2])
    np.testing.assert_array_equal(sim.positions("a"), x)
    sim.step()
    np.testing.assert_array_equal(sim.positions("a"), x), "no gravity: it stays"


def test_a_grabbed_particle_is_dragged_to_its_target_and_released_with_its_velocity():
    sim = weft.Simulation(SMALL)
    start = sim.positions("a")[12]
    goal = start + np.array([0.2, 0.0, 0.0])
    sim.grab("a", 12, goal)
    sim.step()
    np.testing.assert_allclose(sim.positions("a")[12], goal, atol=1e-9)
    sim.release()
    # (0.2 m / 10 substeps) / (1/600 s) = 12 m/s along x, as the viewer's drag.
    np.testing.assert_allclose(sim.velocities("a")[12], [12.0, 0.0, 0.0], atol=1e-6)
    sim.step()
    moved = np.linalg.norm(sim.positions("a")[12] - goal)
    assert moved > 0.05, "free again, the cloth pulls it back"


def test_stats_are_the_logs_stats_of_the_last_frame():
    sim = weft.Simulation(HANGING)
    s0 = sim.stats()
    assert set(s0) == {
        "frame", "time", "kinetic_energy", "residual_max", "residual_rms", "contacts",
        "cg_iterations", "step_ms",
    }
    assert (s0["frame"], s0["kinetic_energy"]) == (0, 0.0)
    sim.step(10)
    s = sim.stats()
    assert s["frame"] == 10 and s["time"] == sim.time
    assert s["kinetic_energy"] > 0.0 and s["residual_max"] > 0.0 and s["step_ms"] > 0.0
    assert s["contacts"] == 0 and s["cg_iterations"] == 0
    # A fabric bends through XPBD's hinges: their residual is reported, and converged.
    cotton = weft.Simulation(HANGING, overrides={"cloth.cloth.material": "cotton"})
    cotton.step(10)
    assert 0.0 <= cotton.stats()["bending_residual"] < 0.05


def test_stepping_releases_the_gil():
    sim = weft.Simulation(
        "assets/scenes/reference.toml", overrides={"cloth.reference.resolution": [64, 64]}
    )
    ticks = []
    done = threading.Event()

    def tick():
        while not done.is_set():
            ticks.append(time.monotonic())
            time.sleep(0.001)

    t = threading.Thread(target=tick)
    start = time.monotonic()
    t.start()
    sim.step(60)
    stepped = time.monotonic()
    done.set()
    t.join()
    during = [x for x in ticks if start < x < stepped]
    assert stepped - start > 0.05, "long enough to tell"
    assert len(during) >= 10, f"the other thread ran {len(during)} times while stepping"
