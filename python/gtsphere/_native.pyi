"""Type hints of gtsphere's native module (the docstrings are on the objects themselves).

Checked against the built module by `python -m mypy.stubtest gtsphere` (python/tests/test_stubs.py):
every name, signature and default here is the one the module has at run time.
"""

from collections.abc import Callable, Sequence
from os import PathLike
from typing import Literal, Optional, TypedDict, Union, final

import numpy as np
import numpy.typing as npt

__all__ = [
    "Error",
    "ParseError",
    "SceneWarning",
    "Scene",
    "Camera",
    "Film",
    "load",
    "render",
    "occlusion",
    "save",
    "compare",
    "__version__",
]

__version__: str

# Type aliases of the stubs only (private: the module does not define them).
_Vec3 = Union[Sequence[float], npt.ArrayLike]
_ArrayLike = npt.ArrayLike
_Path = Union[str, PathLike[str]]
_Integrator = Literal["exact", "march", "mc", "ao"]
_Weighting = Literal["cosine", "uniform"]
_AoMethod = Literal["exact", "mc", "directions", "sum", "voxel"]
_Sampler = Literal["stratified", "center"]
_Aov = Literal["depth", "normal", "id", "ao", "error"]
_Profile = Literal["constant", "linear", "quadratic", "gaussian"]
_Bounds = tuple[tuple[float, float, float], tuple[float, float, float]]

class _Metrics(TypedDict):
    """What compare() returns: the numbers `gtsphere compare` prints."""

    rmse: float
    relative_rmse: float
    psnr: float
    max_abs: float
    max_at: tuple[int, int]

class Error(Exception): ...
class ParseError(Error): ...
class SceneWarning(UserWarning): ...

@final
class Scene:
    @staticmethod
    def from_arrays(
        centers: _ArrayLike,
        radii: Union[float, _ArrayLike],
        colors: Optional[_ArrayLike] = None,
        transparency: Optional[_ArrayLike] = None,
        emissive: Optional[_ArrayLike] = None,
        *,
        headlight: bool = True,
        background: Optional[_Vec3] = None,
        profile: Optional[_Profile] = None,
        profile_width: Optional[float] = None,
    ) -> Scene: ...
    def add_point_light(
        self,
        location: _Vec3,
        color: Optional[_Vec3] = None,
        intensity: float = 1.0,
        ambient_intensity: float = 0.0,
        attenuation: Optional[_Vec3] = None,
        radius: float = 100.0,
    ) -> None: ...
    def add_directional_light(
        self,
        direction: Optional[_Vec3] = None,
        color: Optional[_Vec3] = None,
        intensity: float = 1.0,
        ambient_intensity: float = 0.0,
    ) -> None: ...
    @property
    def headlight(self) -> bool: ...
    @headlight.setter
    def headlight(self, on: bool) -> None: ...
    @property
    def background(self) -> tuple[float, float, float]: ...
    @background.setter
    def background(self, rgb: _Vec3) -> None: ...
    @property
    def bounds(self) -> Optional[_Bounds]: ...
    @property
    def spheres(self) -> int: ...
    def sphere_arrays(
        self,
    ) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
    @property
    def gas_spheres(self) -> int: ...
    @property
    def lights(self) -> int: ...
    @property
    def warnings(self) -> list[str]: ...
    def __len__(self) -> int: ...

def load(
    path: _Path,
    *,
    point_radius: Optional[float] = None,
    spheres_only: bool = False,
    strict: bool = False,
    profile: Optional[_Profile] = None,
    profile_width: Optional[float] = None,
    max_expansion: int = 16,
) -> Scene: ...
@final
class Camera:
    @staticmethod
    def look_at(
        eye: _Vec3,
        target: Optional[_Vec3] = None,
        up: Optional[_Vec3] = None,
        fov: float = 0.7853981633974483,
        ortho_height: Optional[float] = None,
    ) -> Camera: ...
    @staticmethod
    def frame(
        scene: Scene,
        direction: Optional[_Vec3] = None,
        up: Optional[_Vec3] = None,
        fov: float = 0.7853981633974483,
        ortho: bool = False,
        margin: float = 0.02,
    ) -> Camera: ...
    @staticmethod
    def from_scene(
        scene: Scene,
        viewpoint: Optional[str] = None,
        *,
        fov_across: Literal["smaller", "width", "height"] = "smaller",
        size: Optional[tuple[int, int]] = None,
    ) -> Camera: ...
    @property
    def position(self) -> tuple[float, float, float]: ...
    @property
    def forward(self) -> tuple[float, float, float]: ...
    @property
    def up(self) -> tuple[float, float, float]: ...
    @property
    def right(self) -> tuple[float, float, float]: ...
    @property
    def fov(self) -> Optional[float]: ...
    @property
    def ortho_height(self) -> Optional[float]: ...

@final
class Film:
    @property
    def rgb(self) -> npt.NDArray[np.float64]: ...
    @property
    def alpha(self) -> npt.NDArray[np.float64]: ...
    @property
    def error(self) -> npt.NDArray[np.float64]: ...
    @property
    def ao(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def depth(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def normal(self) -> Optional[npt.NDArray[np.float64]]: ...
    @property
    def id(self) -> Optional[npt.NDArray[np.int64]]: ...
    @property
    def max_error(self) -> float: ...
    @property
    def seconds(self) -> float: ...
    @property
    def counters(self) -> dict[str, int]: ...
    @property
    def width(self) -> int: ...
    @property
    def height(self) -> int: ...
    def _repr_png_(self) -> bytes: ...

def render(
    scene: Scene,
    camera: Optional[Camera],
    width: int,
    height: int,
    *,
    spp: int = 16,
    integrator: _Integrator = "exact",
    tol: float = 1e-4,
    seed: int = 0,
    threads: Optional[int] = None,
    aovs: Sequence[_Aov] = (),
    sampler: _Sampler = "stratified",
    step: Optional[float] = None,
    progress: Optional[Callable[[int, int], object]] = None,
    headlight_shadows: bool = False,
    ao_reach: Optional[float] = None,
    ao_weighting: _Weighting = "cosine",
    ao_colours: bool = False,
    ao_method: _AoMethod = "exact",
    ao_samples: int = 16,
    ao_directions: int = 64,
) -> Film: ...
def occlusion(
    scene: Scene,
    *,
    ao_reach: Optional[float] = None,
    ao_weighting: _Weighting = "cosine",
    tol: float = 1e-3,
    threads: Optional[int] = None,
    progress: Optional[Callable[[int, int], object]] = None,
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def save(image: Union[Film, _ArrayLike], path: _Path) -> None: ...
def compare(
    image: Union[Film, _ArrayLike, _Path], reference: Union[Film, _ArrayLike, _Path]
) -> _Metrics: ...
