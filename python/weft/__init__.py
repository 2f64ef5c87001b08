"""Weft's cloth simulator from Python.

Load a scene (a file or a TOML string), step it with the GIL released, read and set particle
arrays with numpy, drag a particle, change the viewer's live settings, and log MCAP files
identical to ``weft run --out``'s::

    import weft
    sim = weft.Simulation("assets/scenes/hanging.toml", overrides={"sim.substeps": 20})
    sim.step(120)
    print(sim.positions("flag")[:, 1].min())

A sweep over processes: the simulator runs its frames on a thread pool, which a process forked
from one that already stepped does not inherit; give ``ProcessPoolExecutor`` a "spawn" or
"forkserver" ``mp_context``.
"""

from ._weft import (
    SceneError,
    Simulation,
    SimulationError,
    __version__,
    materials,
    methods,
)

__all__ = [
    "SceneError",
    "Simulation",
    "SimulationError",
    "__version__",
    "materials",
    "methods",
]
