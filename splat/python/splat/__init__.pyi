# Type stubs of the package splat (tests/python/test_stubs.py checks them against the module:
# names, methods and every keyword, which are the command line's long options).
from typing import Any, Callable, Iterator, Literal, Sequence, overload

import numpy as np
from numpy.typing import ArrayLike, NDArray

__version__: str

Progress = Callable[[int, int, str], bool | None]
# A Gaussian scene where a volume is taken: splat.Gaussians, a .ply path or 'gaussians:NAME'.
SceneInput = Volume | Gaussians | str

class Error(Exception): ...
class InputError(Error, ValueError): ...
class FileError(Error, OSError): ...
class Cancelled(Error): ...

class Volume:
    def __init__(
        self,
        array: ArrayLike,
        spacing: Sequence[float] = ...,
        origin: Sequence[float] = ...,
        *,
        order: Literal["zyx", "xyz"] = ...,
        background_value: float | None = ...,
        nan_policy: Literal["error", "zero"] = ...,
    ) -> None: ...
    @property
    def array(self) -> NDArray[Any]: ...
    @property
    def shape(self) -> tuple[int, int, int]: ...
    @property
    def dims(self) -> tuple[int, int, int]: ...
    @property
    def spacing(self) -> tuple[float, float, float]: ...
    @property
    def origin(self) -> tuple[float, float, float]: ...
    @property
    def center(self) -> tuple[float, float, float]: ...
    @property
    def orientation(self) -> NDArray[np.float64]: ...
    @property
    def affine(self) -> NDArray[np.float64]: ...
    @property
    def value_range(self) -> tuple[float, float]: ...
    @property
    def background_value(self) -> float: ...
    @property
    def background_source(self) -> str: ...
    @property
    def source(self) -> str: ...
    @property
    def notes(self) -> list[str]: ...
    @property
    def dtype(self) -> str: ...
    @property
    def borrowed(self) -> bool: ...
    @property
    def nbytes(self) -> int: ...
    def describe(self) -> str: ...
    def save(self, path: str) -> None: ...

class TransferFunction:
    def __init__(
        self,
        points: ArrayLike,
        *,
        normalized: bool = ...,
        unit_distance: float = ...,
        mode: str | None = ...,
        name: str = ...,
    ) -> None: ...
    @staticmethod
    def preset(name: str) -> TransferFunction: ...
    @staticmethod
    def presets() -> list[str]: ...
    @staticmethod
    def from_json(path: str) -> TransferFunction: ...
    @staticmethod
    def load(name_or_path: str) -> TransferFunction: ...
    name: str
    @property
    def points(self) -> NDArray[np.float32]: ...
    @property
    def normalized(self) -> bool: ...
    @property
    def unit_distance(self) -> float: ...
    @property
    def mode(self) -> str | None: ...
    def sample(self, values: ArrayLike) -> NDArray[np.float32]: ...
    def extinction(self, value: float) -> float: ...
    def resolved(self, low: float, high: float) -> TransferFunction: ...
    def rescaled_to_data(self) -> TransferFunction: ...
    def to_json(self) -> str: ...

def load(
    path: str,
    *,
    dims: tuple[int, int, int] | str | None = ...,
    type: str | None = ...,
    spacing: Sequence[float] | str | None = ...,
    big_endian: bool | None = ...,
    header_bytes: int | None = ...,
    nan_policy: str | None = ...,
    allow_outside_data: bool | None = ...,
    series: str | None = ...,
    time: int | None = ...,
    background_value: float | str | None = ...,
    grid: str | None = ...,
    zarr_level: int | str | None = ...,
    channel: int | str | None = ...,
) -> Volume: ...
def load_options() -> list[str]: ...
def zarr_level(path: str, **options: Any) -> int: ...
def synthetic(name: str, size: int | None = ...) -> Volume: ...
def synthetic_names() -> list[str]: ...
def from_nibabel(
    img: Any, *, background_value: float | None = ..., nan_policy: str = ...
) -> Volume: ...
def list_dicom_series(folder: str) -> list[dict[str, Any]]: ...
def render_options() -> list[str]: ...
def load_scene(path: str) -> dict[str, Any]: ...
def render_scene(
    path: str, *, progress: Progress | None = ..., return_stats: bool = ..., **overrides: Any
) -> Any: ...
def save_scene(path: str, volume: str, *, command: str = ..., **options: Any) -> None: ...
def render(
    volume: SceneInput,
    *,
    progress: Progress | None = ...,
    return_stats: bool = ...,
    mode: str | None = ...,
    classify: str | None = ...,
    tf: str | TransferFunction | ArrayLike | None = ...,
    iso_level: float | str | None = ...,
    size: tuple[int, int] | str | None = ...,
    azimuth: float | None = ...,
    elevation: float | None = ...,
    projection: str | None = ...,
    pixel_size: float | None = ...,
    fov: float | None = ...,
    distance: float | None = ...,
    eye: Sequence[float] | str | None = ...,
    look_at: Sequence[float] | str | None = ...,
    up: Sequence[float] | str | None = ...,
    renderer: str | None = ...,
    order: str | None = ...,
    kernel: str | None = ...,
    sigma: float | None = ...,
    radius: float | None = ...,
    background: Sequence[float] | str | None = ...,
    shade: bool | None = ...,
    quality: str | None = ...,
    slab: float | None = ...,
    early_termination: float | None = ...,
    ref_step: float | None = ...,
    ref_tolerance: float | None = ...,
    threads: int | None = ...,
    tile_size: int | None = ...,
    warp_tolerance: float | None = ...,
    lod: float | None = ...,
    pixel_filter: float | None = ...,
    ewa: str | None = ...,
    iso_normalized: bool | None = ...,
    edges: Sequence[float] | str | None = ...,
    clip_plane: Sequence[float] | Sequence[Sequence[float]] | str | None = ...,
    crop: Sequence[float] | str | None = ...,
    label_volume: str | None = ...,
    label_colors: str | None = ...,
    label_names: str | None = ...,
    labels: Sequence[float] | str | None = ...,
    label_opacity: float | None = ...,
    tf_rescale: bool | None = ...,
    ambient: float | None = ...,
    diffuse: float | None = ...,
    specular: float | None = ...,
    shininess: float | None = ...,
    light: str | Sequence[float] | None = ...,
    scene: str | None = ...,
) -> Any: ...

class Scene:
    volume: Volume | Gaussians
    options: dict[str, Any]
    def __init__(
        self,
        volume: SceneInput,
    mode: str | None = ...,
    classify: str | None = ...,
    tf: str | TransferFunction | ArrayLike | None = ...,
    iso_level: float | str | None = ...,
    size: tuple[int, int] | str | None = ...,
    azimuth: float | None = ...,
    elevation: float | None = ...,
    projection: str | None = ...,
    pixel_size: float | None = ...,
    fov: float | None = ...,
    distance: float | None = ...,
    eye: Sequence[float] | str | None = ...,
    look_at: Sequence[float] | str | None = ...,
    up: Sequence[float] | str | None = ...,
    renderer: str | None = ...,
    order: str | None = ...,
    kernel: str | None = ...,
    sigma: float | None = ...,
    radius: float | None = ...,
    background: Sequence[float] | str | None = ...,
    shade: bool | None = ...,
    quality: str | None = ...,
    slab: float | None = ...,
    early_termination: float | None = ...,
    ref_step: float | None = ...,
    ref_tolerance: float | None = ...,
    threads: int | None = ...,
    tile_size: int | None = ...,
    warp_tolerance: float | None = ...,
    lod: float | None = ...,
    pixel_filter: float | None = ...,
    ewa: str | None = ...,
    iso_normalized: bool | None = ...,
    edges: Sequence[float] | str | None = ...,
    clip_plane: Sequence[float] | Sequence[Sequence[float]] | str | None = ...,
    crop: Sequence[float] | str | None = ...,
    label_volume: str | None = ...,
    label_colors: str | None = ...,
    label_names: str | None = ...,
    labels: Sequence[float] | str | None = ...,
    label_opacity: float | None = ...,
    tf_rescale: bool | None = ...,
    ambient: float | None = ...,
    diffuse: float | None = ...,
    specular: float | None = ...,
    shininess: float | None = ...,
    light: str | Sequence[float] | None = ...,
    scene: str | None = ...,
    ) -> None: ...
    def render(
        self,
        *,
        progress: Progress | None = ...,
        return_stats: bool = ...,
    mode: str | None = ...,
    classify: str | None = ...,
    tf: str | TransferFunction | ArrayLike | None = ...,
    iso_level: float | str | None = ...,
    size: tuple[int, int] | str | None = ...,
    azimuth: float | None = ...,
    elevation: float | None = ...,
    projection: str | None = ...,
    pixel_size: float | None = ...,
    fov: float | None = ...,
    distance: float | None = ...,
    eye: Sequence[float] | str | None = ...,
    look_at: Sequence[float] | str | None = ...,
    up: Sequence[float] | str | None = ...,
    renderer: str | None = ...,
    order: str | None = ...,
    kernel: str | None = ...,
    sigma: float | None = ...,
    radius: float | None = ...,
    background: Sequence[float] | str | None = ...,
    shade: bool | None = ...,
    quality: str | None = ...,
    slab: float | None = ...,
    early_termination: float | None = ...,
    ref_step: float | None = ...,
    ref_tolerance: float | None = ...,
    threads: int | None = ...,
    tile_size: int | None = ...,
    warp_tolerance: float | None = ...,
    lod: float | None = ...,
    pixel_filter: float | None = ...,
    ewa: str | None = ...,
    iso_normalized: bool | None = ...,
    edges: Sequence[float] | str | None = ...,
    clip_plane: Sequence[float] | Sequence[Sequence[float]] | str | None = ...,
    crop: Sequence[float] | str | None = ...,
    label_volume: str | None = ...,
    label_colors: str | None = ...,
    label_names: str | None = ...,
    labels: Sequence[float] | str | None = ...,
    label_opacity: float | None = ...,
    tf_rescale: bool | None = ...,
    ambient: float | None = ...,
    diffuse: float | None = ...,
    specular: float | None = ...,
    shininess: float | None = ...,
    light: str | Sequence[float] | None = ...,
    scene: str | None = ...,
    ) -> Any: ...
    def iso_depth(self, *, progress: Progress | None = ..., **frame: Any) -> NDArray[np.float32]: ...
    def rotate(
        self,
        frames: int = ...,
        *,
        from_: float = ...,
        to: float | None = ...,
        sweep: str = ...,
        path: str | None = ...,
        parallel_frames: int = ...,
        progress: Progress | None = ...,
        batch: int = ...,
    ) -> Iterator[NDArray[np.float32]]: ...
    @property
    def splat_count(self) -> int: ...
    @property
    def transfer(self) -> TransferFunction: ...

def rotate(
    volume: Volume,
    frames: int = ...,
    *,
    from_: float = ...,
    to: float | None = ...,
    sweep: str = ...,
    path: str | None = ...,
    parallel_frames: int = ...,
    progress: Progress | None = ...,
    mode: str | None = ...,
    classify: str | None = ...,
    tf: str | TransferFunction | ArrayLike | None = ...,
    iso_level: float | str | None = ...,
    size: tuple[int, int] | str | None = ...,
    azimuth: float | None = ...,
    elevation: float | None = ...,
    projection: str | None = ...,
    pixel_size: float | None = ...,
    fov: float | None = ...,
    distance: float | None = ...,
    eye: Sequence[float] | str | None = ...,
    look_at: Sequence[float] | str | None = ...,
    up: Sequence[float] | str | None = ...,
    renderer: str | None = ...,
    order: str | None = ...,
    kernel: str | None = ...,
    sigma: float | None = ...,
    radius: float | None = ...,
    background: Sequence[float] | str | None = ...,
    shade: bool | None = ...,
    quality: str | None = ...,
    slab: float | None = ...,
    early_termination: float | None = ...,
    ref_step: float | None = ...,
    ref_tolerance: float | None = ...,
    threads: int | None = ...,
    tile_size: int | None = ...,
    warp_tolerance: float | None = ...,
    lod: float | None = ...,
    pixel_filter: float | None = ...,
    ewa: str | None = ...,
    iso_normalized: bool | None = ...,
    edges: Sequence[float] | str | None = ...,
    clip_plane: Sequence[float] | Sequence[Sequence[float]] | str | None = ...,
    crop: Sequence[float] | str | None = ...,
    label_volume: str | None = ...,
    label_colors: str | None = ...,
    label_names: str | None = ...,
    labels: Sequence[float] | str | None = ...,
    label_opacity: float | None = ...,
    tf_rescale: bool | None = ...,
    ambient: float | None = ...,
    diffuse: float | None = ...,
    specular: float | None = ...,
    shininess: float | None = ...,
    light: str | Sequence[float] | None = ...,
    scene: str | None = ...,
) -> Iterator[NDArray[np.float32]]: ...
def read_image(path: str) -> NDArray[np.float32]: ...
def write_image(
    path: str,
    image: ArrayLike,
    *,
    window: tuple[float, float] | None = ...,
    bit_depth: int = ...,
    alpha: bool = ...,
) -> None: ...
def default_window(image: ArrayLike) -> tuple[float, float]: ...
def compare(
    test: ArrayLike | str, reference: ArrayLike | str, *, flip: bool = ..., ppd: float = ...
) -> dict[str, float]: ...
def flip_map(test: ArrayLike, reference: ArrayLike, ppd: float = ...) -> NDArray[np.float32]: ...
def write_heatmap(path: str, test: ArrayLike, reference: ArrayLike, scale: float = ...) -> None: ...

class PoppingResult:
    @property
    def angles(self) -> NDArray[np.float64]: ...
    @property
    def renderers(self) -> list[str]: ...
    @property
    def series(self) -> dict[str, dict[str, Any]]: ...
    @property
    def cross_jump(self) -> NDArray[np.float64]: ...
    @property
    def predicted_switches(self) -> NDArray[np.float64]: ...
    @property
    def predicted_name(self) -> str: ...
    @property
    def events(self) -> list[dict[str, Any]]: ...
    @property
    def truth_filter(self) -> float: ...
    @property
    def total_ms(self) -> float: ...
    def write_report(self, folder: str, command_line: str = ...) -> None: ...

def popping(
    volume: SceneInput,
    *,
    progress: Progress | None = ...,
    from_: float = ...,
    to: float = ...,
    step: float = ...,
    sweep: str = ...,
    path: str | None = ...,
    frames: int = ...,
    renderers: str | Sequence[str] = ...,
    refine: int = ...,
    threshold_k: float = ...,
    threshold_floor: float = ...,
    ppd: float = ...,
    no_flip: bool = ...,
    truth: str = ...,
    mode: str | None = ...,
    classify: str | None = ...,
    tf: str | TransferFunction | ArrayLike | None = ...,
    iso_level: float | str | None = ...,
    size: tuple[int, int] | str | None = ...,
    azimuth: float | None = ...,
    elevation: float | None = ...,
    projection: str | None = ...,
    pixel_size: float | None = ...,
    fov: float | None = ...,
    distance: float | None = ...,
    eye: Sequence[float] | str | None = ...,
    look_at: Sequence[float] | str | None = ...,
    up: Sequence[float] | str | None = ...,
    renderer: str | None = ...,
    order: str | None = ...,
    kernel: str | None = ...,
    sigma: float | None = ...,
    radius: float | None = ...,
    background: Sequence[float] | str | None = ...,
    shade: bool | None = ...,
    quality: str | None = ...,
    slab: float | None = ...,
    early_termination: float | None = ...,
    ref_step: float | None = ...,
    ref_tolerance: float | None = ...,
    threads: int | None = ...,
    tile_size: int | None = ...,
    warp_tolerance: float | None = ...,
    lod: float | None = ...,
    pixel_filter: float | None = ...,
    ewa: str | None = ...,
    iso_normalized: bool | None = ...,
    edges: Sequence[float] | str | None = ...,
    clip_plane: Sequence[float] | Sequence[Sequence[float]] | str | None = ...,
    crop: Sequence[float] | str | None = ...,
    label_volume: str | None = ...,
    label_colors: str | None = ...,
    label_names: str | None = ...,
    labels: Sequence[float] | str | None = ...,
    label_opacity: float | None = ...,
    tf_rescale: bool | None = ...,
    ambient: float | None = ...,
    diffuse: float | None = ...,
    specular: float | None = ...,
    shininess: float | None = ...,
    light: str | Sequence[float] | None = ...,
    scene: str | None = ...,
) -> PoppingResult: ...

class StudyResult:
    @property
    def points(self) -> list[dict[str, Any]]: ...
    @property
    def convergence(self) -> list[dict[str, Any]]: ...
    @property
    def visible_voxels(self) -> int: ...
    @property
    def total_ms(self) -> float: ...
    def write_report(self, folder: str, command_line: str = ...) -> None: ...

def study(
    volume: Volume,
    *,
    sweep: dict[str, Sequence[Any]] | Sequence[str] = ...,
    views: Sequence[tuple[float, float]] = ...,
    repeats: int = ...,
    warmup: int = ...,
    truth_step: float = ...,
    truth_tolerance: float = ...,
    ppd: float = ...,
    convergence: bool = ...,
    cache_dir: str | None = ...,
    truth: str = ...,
    progress: Progress | None = ...,
    mode: str | None = ...,
    classify: str | None = ...,
    tf: str | TransferFunction | ArrayLike | None = ...,
    iso_level: float | str | None = ...,
    size: tuple[int, int] | str | None = ...,
    azimuth: float | None = ...,
    elevation: float | None = ...,
    projection: str | None = ...,
    pixel_size: float | None = ...,
    fov: float | None = ...,
    distance: float | None = ...,
    eye: Sequence[float] | str | None = ...,
    look_at: Sequence[float] | str | None = ...,
    up: Sequence[float] | str | None = ...,
    renderer: str | None = ...,
    order: str | None = ...,
    kernel: str | None = ...,
    sigma: float | None = ...,
    radius: float | None = ...,
    background: Sequence[float] | str | None = ...,
    shade: bool | None = ...,
    quality: str | None = ...,
    slab: float | None = ...,
    early_termination: float | None = ...,
    ref_step: float | None = ...,
    ref_tolerance: float | None = ...,
    threads: int | None = ...,
    tile_size: int | None = ...,
    warp_tolerance: float | None = ...,
    lod: float | None = ...,
    pixel_filter: float | None = ...,
    ewa: str | None = ...,
    iso_normalized: bool | None = ...,
    edges: Sequence[float] | str | None = ...,
    clip_plane: Sequence[float] | Sequence[Sequence[float]] | str | None = ...,
    crop: Sequence[float] | str | None = ...,
    label_volume: str | None = ...,
    label_colors: str | None = ...,
    label_names: str | None = ...,
    labels: Sequence[float] | str | None = ...,
    label_opacity: float | None = ...,
    tf_rescale: bool | None = ...,
    ambient: float | None = ...,
    diffuse: float | None = ...,
    specular: float | None = ...,
    shininess: float | None = ...,
    light: str | Sequence[float] | None = ...,
    scene: str | None = ...,
) -> StudyResult: ...
def study_knobs() -> list[str]: ...

class Mesh:
    @property
    def vertices(self) -> NDArray[np.float32]: ...
    @property
    def normals(self) -> NDArray[np.float32]: ...
    @property
    def triangles(self) -> NDArray[np.uint32]: ...
    @property
    def max_residual(self) -> float: ...
    def write(self, path: str) -> None: ...

class Gaussians:
    def __init__(
        self,
        means: NDArray[np.float32],
        scales: NDArray[np.float32],
        rotations: NDArray[np.float32],
        opacities: NDArray[np.float32],
        sh: NDArray[np.float32],
    ) -> None: ...
    @property
    def borrowed(self) -> bool: ...
    @property
    def sh_degree(self) -> int: ...
    @property
    def source(self) -> str: ...
    @property
    def means(self) -> NDArray[np.float32]: ...
    @property
    def scales(self) -> NDArray[np.float32]: ...
    @property
    def rotations(self) -> NDArray[np.float32]: ...
    @property
    def opacities(self) -> NDArray[np.float32]: ...
    @property
    def sh(self) -> NDArray[np.float32]: ...
    def write(self, path: str) -> None: ...

def load_gaussians(path: str) -> Gaussians: ...
def render_gaussians(
    scene: Gaussians,
    *,
    renderer: str = ...,
    width: int = ...,
    height: int = ...,
    azimuth: float = ...,
    elevation: float = ...,
    projection: str = ...,
    pixel_size: float = ...,
    fov: float = ...,
    slab: float = ...,
    ref_tolerance: float = ...,
    threads: int = ...,
) -> NDArray[np.float32]: ...

def iso_surface(
    volume: Volume,
    level: float,
    *,
    kernel: str = ...,
    sigma: float = ...,
    radius: float = ...,
    threads: int = ...,
) -> Mesh: ...
