"""Type stubs of weft._weft, the native module re-exported by the weft package."""

import os
import pathlib
from typing import Any, Dict, List, Mapping, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

__version__: str

class SceneError(ValueError):
    """A scene that does not load or validate: one line per problem, FILE:LINE: key: message."""

class SimulationError(RuntimeError):
    """The simulation diverged; the message is the solver's."""

def methods() -> List[str]:
    """The methods a scene or ``Simulation.set("sim.method", ...)`` may name."""

def materials() -> List[str]:
    """The fabric presets a cloth's ``material`` may name."""

_Value = Union[bool, int, float, str, Sequence[Any], Mapping[str, Any]]
_Vec3 = Union[Sequence[float], npt.NDArray[np.float64]]

class Simulation:
    """A Weft scene and its solvers (one per method in the scene), stepped in lockstep."""

    def __init__(
        self,
        scene: Union[str, "os.PathLike[str]"],
        overrides: Optional[Dict[str, _Value]] = None,
        method: Optional[str] = None,
    ) -> None: ...
    def step(self, frames: int = 1) -> None:
        """Steps ``frames`` frames with the GIL released; Ctrl-C raises KeyboardInterrupt."""
    @property
    def time(self) -> float:
        """Simulated time (s)."""
    @property
    def frame(self) -> int:
        """Frames stepped so far."""
    @property
    def dt(self) -> float:
        """The frame time step in use (s)."""
    @property
    def cloths(self) -> List[str]:
        """The names of the scene's cloths."""
    def positions(self, name: str) -> npt.NDArray[np.float64]:
        """Positions of cloth ``name`` (m), a new (n, 3) float64 array."""
    def velocities(self, name: str) -> npt.NDArray[np.float64]:
        """Velocities of cloth ``name`` (m/s), a new (n, 3) float64 array."""
    def set_positions(self, name: str, positions: npt.NDArray[np.float64]) -> None:
        """Places cloth ``name``'s particles at ``positions`` ((n, 3) float64, finite)."""
    def triangles(self, name: str) -> npt.NDArray[np.uint32]:
        """The triangles of cloth ``name``, a new (m, 3) uint32 array."""
    def grab(self, name: str, index: int, target: _Vec3) -> None:
        """Holds particle ``index`` of cloth ``name`` and drags it to ``target`` (m)."""
    def release(self) -> None:
        """Lets the grabbed particle go; it keeps its drag velocity."""
    def stats(self) -> Dict[str, Union[int, float]]:
        """The last frame's statistics, as the log's /stats channel has them."""
    def set(self, key: str, value: Union[int, float, str, _Vec3]) -> None:
        """Changes a live setting (``sim.substeps``, ``cloth.<name>.stretch_compliance``, ...)."""
    def record(
        self,
        path: Union[str, "os.PathLike[str]"],
        frames: Optional[int] = None,
        log: str = "particles",
        every: int = 1,
        mesh_every: int = 1,
        precision: str = "f32",
        compression: str = "none",
        timing: bool = False,
    ) -> None:
        """Starts an MCAP log at ``path``, as ``weft run --out`` writes it."""
    def stop_recording(self) -> Optional[pathlib.Path]:
        """Finishes the log and returns its path (None when not recording)."""
