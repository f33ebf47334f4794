"""Type hints of gtsphere's native module (the docstrings are on the objects themselves)."""

from collections.abc import Callable, Iterable, Sequence
from os import PathLike
from typing import Literal, Optional, Union

import numpy as np
import numpy.typing as npt

__version__: str

Vec3 = Union[Sequence[float], npt.ArrayLike]
ArrayLike = npt.ArrayLike
PathType = Union[str, PathLike[str]]
Integrator = Literal["exact", "march", "mc"]
Sampler = Literal["stratified", "center"]
Aov = Literal["depth", "normal", "id", "error"]

class Error(Exception): ...
class ParseError(Error): ...
class SceneWarning(UserWarning): ...

class Scene:
    @staticmethod
    def from_arrays(
        centers: ArrayLike,
        radii: Union[float, ArrayLike],
        colors: Optional[ArrayLike] = None,
        transparency: Optional[ArrayLike] = None,
        emissive: Optional[ArrayLike] = None,
        *,
        headlight: bool = True,
        background: Optional[Vec3] = None,
        profile: Optional[str] = None,
        profile_width: Optional[float] = None,
    ) -> Scene: ...
    def add_point_light(
        self,
        location: Vec3,
        color: Optional[Vec3] = None,
        intensity: float = 1.0,
        ambient_intensity: float = 0.0,
        attenuation: Optional[Vec3] = None,
        radius: float = 100.0,
    ) -> None: ...
    def add_directional_light(
        self,
        direction: Optional[Vec3] = None,
        color: Optional[Vec3] = None,
        intensity: float = 1.0,
        ambient_intensity: float = 0.0,
    ) -> None: ...
    headlight: bool
    background: tuple[float, float, float]
    @property
    def bounds(
        self,
    ) -> Optional[tuple[tuple[float, float, float], tuple[float, float, float]]]: ...
    @property
    def spheres(self) -> int: ...
    @property
    def gas_spheres(self) -> int: ...
    @property
    def lights(self) -> int: ...
    @property
    def warnings(self) -> list[str]: ...
    def __len__(self) -> int: ...

def load(
    path: PathType,
    *,
    point_radius: Optional[float] = None,
    spheres_only: bool = False,
    strict: bool = False,
    profile: Optional[str] = None,
    profile_width: Optional[float] = None,
) -> Scene: ...

class Camera:
    @staticmethod
    def look_at(
        eye: Vec3,
        target: Optional[Vec3] = None,
        up: Optional[Vec3] = None,
        fov: float = 0.7853981633974483,
        ortho_height: Optional[float] = None,
    ) -> Camera: ...
    @staticmethod
    def frame(
        scene: Scene,
        direction: Optional[Vec3] = None,
        up: Optional[Vec3] = None,
        fov: float = 0.7853981633974483,
        ortho: bool = False,
        margin: float = 0.02,
    ) -> Camera: ...
    @staticmethod
    def from_scene(scene: Scene, viewpoint: Optional[str] = None) -> Camera: ...
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

class Film:
    @property
    def rgb(self) -> npt.NDArray[np.float64]: ...
    @property
    def alpha(self) -> npt.NDArray[np.float64]: ...
    @property
    def error(self) -> npt.NDArray[np.float64]: ...
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
    integrator: Integrator = "exact",
    tol: float = 1e-4,
    seed: int = 0,
    threads: Optional[int] = None,
    aovs: Iterable[Aov] = (),
    sampler: Sampler = "stratified",
    step: Optional[float] = None,
    progress: Optional[Callable[[int, int], object]] = None,
    headlight_shadows: bool = False,
) -> Film: ...
def save(image: Union[Film, ArrayLike], path: PathType) -> None: ...
def compare(
    image: Union[Film, ArrayLike, PathType], reference: Union[Film, ArrayLike, PathType]
) -> dict[str, object]: ...
