# Type stubs of the `texel` package (the pybind11 extension texel._texel,
# re-exported by texel/__init__.py). tests/python/test_stub.py checks that
# every public name of the module appears here.
from os import PathLike
from typing import Any, Iterator, Literal, Optional, Sequence, Union

import numpy as np
import numpy.typing as npt

from . import experiment as experiment

__version__: str
__all__: list[str]

_Path = Union[str, PathLike[str]]
_Array = npt.ArrayLike
_DType = Literal["native", "float64", "uint16", "uint8", "float32"]
_Device = Union[str, "DeviceProfile"]
_Coarse = Union["ConstantProfile", "SineProfile", "ValuesProfile", "PointsProfile", "SampledProfile", None]
_Choice = Literal["a", "b", "unsure", "A", "B"]

# ------------------------------------------------------------------ errors
class Error(RuntimeError): ...
class InvalidArgument(Error, ValueError): ...
class FormatError(Error): ...
class IoError(Error, OSError): ...

# ----------------------------------------------------------------- devices
class DeviceProfile:
    name: str
    description: str
    samples: int
    spacing_mm: float
    format: str
    refresh_hz: float
    band_min_cpm: float
    band_max_cpm: float
    length_mm: float
    nyquist_cpm: float
    positions_mm: npt.NDArray[np.float64]
    def to_json(self) -> str: ...

def device(name_or_path: str = "tpad", *, length_mm: Optional[float] = None,
           spacing_mm: Optional[float] = None) -> DeviceProfile: ...
def builtin_devices() -> list[str]: ...

# --------------------------------------------------------- coarse profiles
class ConstantProfile:
    value: float
    def __init__(self, value: float = 1.0) -> None: ...

class SineProfile:
    period_mm: float
    phase_deg: float
    def __init__(self, period_mm: float = 5.0, phase_deg: float = 0.0) -> None: ...

class ValuesProfile:
    values: list[float]
    def __init__(self, values: Sequence[float]) -> None: ...

class PointsProfile:
    points: list[tuple[float, float]]
    def __init__(self, points: Sequence[tuple[float, float]]) -> None: ...

class SampledProfile:
    spacing_mm: float
    values: list[float]
    def __init__(self, spacing_mm: float, values: Sequence[float]) -> None: ...

def read_profile_csv(path: str) -> PointsProfile: ...

# --------------------------------------------------------------- documents
class Document:
    version: int
    description: str
    device: DeviceProfile
    regions: list[dict[str, Any]]
    def to_json(self) -> str: ...
    def save(self, path: str) -> None: ...
    def render(self, *, dtype: _DType = "native") -> npt.NDArray[Any]: ...

def load_document(path: str) -> Document: ...
def parse_document(json_text: str, origin: str = "document") -> Document: ...
def save_document(document: Document, path: str) -> None: ...
def document_json(document: Document) -> str: ...
def document(*, central_pitch_db: float = 10.0, irregularity_db: float = -5.0, texel_length_mm: float = 0.25,
             seed: int = 1, parameterization: str = "moments", out_of_band: str = "redraw",
             band_min_cpm: float = 0.01, band_max_cpm: float = 0.0, quantization_db: float = 0.0,
             phase: str = "continuous", fill: str = "whole", coarse_strength: float = 0.0,
             fine_strength: float = 1.0, coarse: _Coarse = None, device: _Device = "tpad",
             length_mm: Optional[float] = None, spacing_mm: Optional[float] = None,
             description: str = "") -> Document: ...
def render_document(document: Document, *, dtype: _DType = "native") -> npt.NDArray[Any]: ...

# --------------------------------------------------------------- rendering
def render(*, central_pitch_db: float = 10.0, irregularity_db: float = -5.0, texel_length_mm: float = 0.25,
           seed: int = 1, parameterization: str = "moments", out_of_band: str = "redraw",
           band_min_cpm: float = 0.01, band_max_cpm: float = 0.0, quantization_db: float = 0.0,
           phase: str = "continuous", fill: str = "whole", coarse_strength: float = 0.0,
           fine_strength: float = 1.0, coarse: _Coarse = None, device: _Device = "tpad",
           length_mm: Optional[float] = None, spacing_mm: Optional[float] = None,
           dtype: _DType = "native") -> npt.NDArray[Any]: ...
def texels(document: Document) -> dict[str, npt.NDArray[Any]]: ...

# -------------------------------------------------------------- references
def reference(name: str, *, device: _Device = "tpad", seed: int = 1, length_mm: Optional[float] = None,
              spacing_mm: Optional[float] = None, dtype: _DType = "native", **params: Any) -> npt.NDArray[Any]: ...
def reference_document(name: str, *, device: _Device = "tpad", seed: int = 1, length_mm: Optional[float] = None,
                       spacing_mm: Optional[float] = None, **params: Any) -> Document: ...
def reference_names() -> list[str]: ...
def reference_info(name: str) -> dict[str, Any]: ...

# ------------------------------------------------------------------- codec
class Bitstream:
    central_pitch_db: float
    irregularity_db: float
    texel_length_mm: float
    seed: int
    has_coarse: bool
    coarse_levels: npt.NDArray[np.uint16]
    spec: dict[str, Any]
    def to_bytes(self) -> bytes: ...

def parse_bitstream(data: bytes) -> Bitstream: ...
def bitstream_from_document(document: Document, *, bits: int = 8) -> Bitstream: ...

class Transcoded:
    bytes: bytes
    bitstream: Bitstream
    spec: dict[str, Any]
    exact: bool
    losses: list[str]

def transcode(source: Union[Document, bytes, Bitstream, _Path], *, coarse_bits: Optional[int] = None,
              max_bytes: Optional[int] = None, device: Optional[_Device] = None) -> Transcoded: ...
def decode_document(source: Union[bytes, Bitstream, _Path], *, device: _Device = "tpad",
                    length_mm: Optional[float] = None, spacing_mm: Optional[float] = None) -> Document: ...
def decode(source: Union[bytes, Bitstream, _Path], *, device: _Device = "tpad", length_mm: Optional[float] = None,
           spacing_mm: Optional[float] = None, dtype: _DType = "native") -> npt.NDArray[Any]: ...

def export_hjif(document: Document, *, modality: str = "friction", tolerance: float = 1.0 / 512,
                date: str = "") -> dict[str, Any]: ...
def export_gltf(document: Document, *, hjif_uri: str, container: str = "gltf", modality: str = "friction",
                width_mm: float = 25.0) -> bytes: ...
def hjif_conformance_errors(text: str) -> list[str]: ...

class EncodeResult:
    bytes: bytes
    bitstream: Bitstream
    spec: dict[str, Any]
    central_pitch_db: float
    irregularity_db: float
    texel_length_mm: float
    coarse_strength: float
    fine_strength: float
    percept: dict[str, float]
    decoded_percept: dict[str, float]
    distance_jnd: float
    model_distance: float  # old name of distance_jnd
    model_version: int
    target: Literal["felt", "centroid"]
    beyond_felt_band: float
    warnings: list[str]
    no_texture: bool
    at_bound: dict[str, bool]
    def to_json(self) -> str: ...
    coarse: bool
    coarse_correlation: float
    texel_recovered: bool
    irregularity_identifiable: bool
    irregularity_bound_db: float
    evaluations: int
    seconds: float
    samples: int
    spacing_mm: float

class Encode2DResult:
    document: Document
    coarse_image: Optional[npt.NDArray[np.float32]]
    spec: dict[str, Any]
    central_pitch_db: float
    irregularity_db: float
    texel_length_mm: float
    field: Literal["spectral", "cells", "oriented"]
    per_direction: list[dict[str, Any]]
    central_pitch_spread_db: float
    irregularity_spread_db: float
    anisotropic: bool
    strongest_direction_deg: float
    mean_central_pitch_db: float
    mean_irregularity_db: float
    irregularity_identifiable: bool
    irregularity_bound_db: float
    texel_length_detected: bool
    coarse: bool
    no_texture: bool
    texture_rms: float
    model_version: int
    target: Literal["felt", "centroid"]
    correction_rounds: int
    correction_residual_db: float
    method: Literal["bitmap", "scans"]
    def to_json(self) -> str: ...
    def save(self, path: _Path) -> None: ...

def encode_2d(source: Union[_Path, _Array], *, pitch_mm: Optional[float] = None, device: Optional[_Device] = None,
              polarity: Optional[Literal["darker_more_friction", "brighter_more_friction"]] = None,
              directions: int = 18, scan_samples: int = 16384, correction_rounds: int = 1,
              field: Optional[Literal["spectral", "cells", "oriented"]] = None, detect_lattice: bool = True,
              coarse_image_path: str = "coarse.npy", swipe_speed_mm_s: Optional[float] = None,
              boundary_mm: float = 1.0, texel_length_mm: float = 0.25, seed: int = 1,
              parameterization: str = "moments", model: int = 2,
              target: Literal["automatic", "felt", "centroid"] = "automatic",
              no_texture: Literal["flag", "refuse"] = "flag") -> Encode2DResult: ...

# ---------------------------------------------------------------- signals
class Signal:
    samples: npt.NDArray[np.float64]
    spacing_mm: float
    origin_mm: float
    length_mm: float
    format: str
    scaled: bool
    sample_rate_hz: Optional[float]
    description: str
    def __len__(self) -> int: ...

def load_signal(source: Union[_Path, _Array], *, device: Optional[_Device] = None, spacing_mm: Optional[float] = None,
                region: Union[None, str, tuple[float, float]] = None, swipe_speed_mm_s: Optional[float] = None,
                channel: Union[None, int, Literal["mix"]] = None, max_samples: int = 67108864) -> Signal: ...

def encode(source: Union[_Path, _Array], *, device: Optional[_Device] = None, spacing_mm: Optional[float] = None,
           swipe_speed_mm_s: Optional[float] = None, boundary_mm: float = 1.0, texel_length_mm: float = 0.25,
           seed: int = 1, parameterization: str = "moments", coarse_bits: int = 6,
           max_bytes: Optional[int] = None, fit: str = "least-squares",
           display_response: Literal["device", "flat"] = "device", drawn_weight: float = 1.0, model: int = 2,
           no_texture: Literal["flag", "refuse"] = "flag",
           target: Literal["automatic", "felt", "centroid"] = "automatic") -> EncodeResult: ...

# ---------------------------------------------------------------- spectrum
class Spectrum:
    bin_cpm: float
    resolution_cpm: float
    samples: int
    nfft: int
    frequency_cpm: npt.NDArray[np.float64]
    magnitude: npt.NDArray[np.float64]
    power: npt.NDArray[np.float64]

def magnitude_spectrum(samples: _Array, spacing_mm: float, *, window: str = "blackman-harris", zero_pad: int = 4,
                       remove_mean: bool = True) -> Spectrum: ...
def analyse_spectrum(samples: _Array, spacing_mm: float) -> dict[str, Any]: ...

# ----------------------------------------------------------------- options
_Operation = Literal["render", "encode", "swipe", "play", "player", "path_2d"]
def options(name: _Operation) -> list[dict[str, Any]]: ...

# ------------------------------------------------------------------ player
def simulate_swipe(*, speed_mm_s: float = 100.0, pattern: str = "constant", start_mm: float = 0.0,
                   extent_mm: float = 0.0, surface_mm: float = 0.0, turn_s: float = 0.1, duration_s: float = 1.0,
                   rate_hz: float = 1000.0, lead_in_s: float = 0.0) -> dict[str, npt.NDArray[Any]]: ...
def render_trace(document: Document, t_s: _Array, x_mm: _Array, touch: Optional[_Array] = None, *, duration_s: float,
                 rate_hz: float = 48000.0, output: str = "vibration", carrier_hz: float = 250.0,
                 prediction_s: float = 0.0,
                 gain: float = 1.0, response: str = "limit", band_limit: str = "on") -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
def swipe(document: Document, *, speed_mm_s: float = 100.0, pattern: str = "constant",
          start_mm: float = 0.0, extent_mm: float = 0.0, turn_s: float = 0.1,
          duration_s: float = 2.0, rate_hz: float = 48000.0, output: str = "vibration", carrier_hz: float = 250.0,
          prediction_s: float = 0.0,
          gain: float = 1.0, response: str = "limit", band_limit: str = "on") -> tuple[npt.NDArray[np.float32], npt.NDArray[np.float32]]: ...
def swipe_measures(t_s: _Array, x_mm: _Array, touch: Optional[_Array] = None, *,
                   still_below_mm_s: float = 0.0) -> dict[str, float]: ...

# ------------------------------------------------------------- 2-D surfaces
_Path2D = Literal["line", "circle", "zigzag"]
_Mode2D = Literal["path", "bitmap"]
_AtLift = Literal["keep", "reset"]
_F32 = npt.NDArray[np.float32]

def bitmap_info(device: Union[Document, _Device]) -> Optional[dict[str, Any]]: ...
def render_2d(document: Document, *, dtype: _DType = "float64",
              rows: Optional[tuple[int, int]] = None) -> npt.NDArray[Any]: ...
def coarse_raster(document: Document, *, region: int = 0, pitch_mm: Optional[float] = None) -> dict[str, Any]: ...
def write_bitmap(document: Document, path: _Path, *, depth: int = 0, mat_version: str = "5") -> dict[str, Any]: ...
def simulate_path_2d(*, path: _Path2D = "line", speed_mm_s: float = 100.0, angle_deg: float = 0.0,
                     start_x_mm: float = 0.0, start_y_mm: float = 0.0, radius_mm: float = 20.0, leg_mm: float = 10.0,
                     zigzag_deg: float = 90.0, duration_s: float = 1.0,
                     rate_hz: float = 1000.0) -> npt.NDArray[np.float64]: ...
def render_trace_2d(document: Document, trace: _Array, *, duration_s: Optional[float] = None, mode: _Mode2D = "path",
                    path_at_lift: _AtLift = "keep", rate_hz: float = 48000.0, output: str = "vibration",
                    carrier_hz: float = 250.0, prediction_s: float = 0.0, gain: float = 1.0,
                    response: str = "limit", band_limit: str = "on") -> tuple[_F32, _F32, _F32]: ...
def swipe_2d(document: Document, *, path: _Path2D = "line", speed_mm_s: float = 100.0, angle_deg: float = 0.0,
             start_x_mm: float = 0.0, start_y_mm: float = 0.0, radius_mm: float = 20.0, leg_mm: float = 10.0,
             zigzag_deg: float = 90.0, duration_s: float = 2.0, mode: _Mode2D = "path", path_at_lift: _AtLift = "keep",
             rate_hz: float = 48000.0, output: str = "vibration", carrier_hz: float = 250.0, prediction_s: float = 0.0,
             gain: float = 1.0, response: str = "limit", band_limit: str = "on") -> tuple[_F32, _F32, _F32]: ...

# -------------------------------------------------------------- procedures
class Staircase:
    def __init__(self, start_value: float, step_sizes: Sequence[float], *, n_up: int = 1, n_down: int = 3,
                 n_reversals: Optional[int] = None, n_trials: int = 0, step_type: str = "lin",
                 min_value: Optional[float] = None, max_value: Optional[float] = None,
                 apply_initial_rule: bool = True, end_value: str = "next") -> None: ...
    @staticmethod
    def replay(answers: Sequence[bool], start_value: float, step_sizes: Sequence[float], *, n_up: int = 1,
               n_down: int = 3, n_reversals: Optional[int] = None, n_trials: int = 0, step_type: str = "lin",
               min_value: Optional[float] = None, max_value: Optional[float] = None,
               apply_initial_rule: bool = True, end_value: str = "next") -> Staircase: ...
    def next(self) -> float: ...
    def answer(self, correct: bool) -> None: ...
    finished: bool
    trials: int
    intensities: list[float]
    responses: list[bool]
    reversal_trials: list[int]
    reversal_intensities: list[float]
    last_was_reversal: bool
    current_step: float
    convergent_value: float
    next_value: float
    n_reversals: int
    def mean_last_reversals(self, k: int) -> float: ...
    def mean_reversals_excluding_first(self, k: int) -> float: ...
    def state_json(self) -> str: ...

class MatchPoint:
    pitch_db: float
    irregularity_db: float
    def __init__(self, pitch_db: float, irregularity_db: float) -> None: ...
    def __iter__(self) -> Iterator[float]: ...

_Point = Union[MatchPoint, tuple[float, float]]

class MatchQuestion:
    a: MatchPoint
    b: MatchPoint
    iteration: int
    index: int

class MatchOptimizer:
    def next(self) -> MatchQuestion: ...
    def answer(self, choice: _Choice) -> None: ...
    def replay(self, choices: Sequence[_Choice]) -> None: ...
    def state_json(self) -> str: ...
    finished: bool
    estimate: MatchPoint
    uncertainty: MatchPoint
    comparisons: int
    budget: int
    name: str

class GuidedOptimizer(MatchOptimizer):
    def __init__(self, *, pitch_min_db: float = -20.0, pitch_max_db: float = 19.7, irregularity_min_db: float = -30.0,
                 irregularity_max_db: float = 5.0, iterations: int = 5, shrink_rate: float = 0.2,
                 unsure: str = "ignore", bound: str = "per_axis", seed: int = 1) -> None: ...
    iteration: int
    choices: list[str]
    boxes: dict[str, npt.NDArray[np.float64]]

class BayesOptimizer(MatchOptimizer):
    def __init__(self, *, pitch_min_db: float = -20.0, pitch_max_db: float = 19.7, irregularity_min_db: float = -30.0,
                 irregularity_max_db: float = 5.0, comparisons: int = 20, sd_stop_db: Optional[float] = None,
                 noise_db: float = 2.0, unsure_band_db: float = 1.0, lapse: float = 0.04,
                 irregularity_weight: float = 1.0, grid_step_db: float = 0.5, candidates: int = 64,
                 particles: int = 256, seed: int = 1) -> None: ...
    def likelihood(self, question: MatchQuestion, choice: _Choice, target: _Point) -> float: ...
    choices: list[str]

def optimizer(kind: Literal["guided", "bayesian"], **params: Any) -> MatchOptimizer: ...

# --------------------------------------------------------------- observers
class PsychometricObserver:
    def __init__(self, *, shape: str = "weibull", threshold: float = 1.0, slope: float = 3.0, guess: float = 0.0,
                 lapse: float = 0.0, log_x: bool = False, seed: int = 1) -> None: ...
    def p_correct(self, x: float) -> float: ...
    def inverse(self, p: float) -> float: ...
    def respond(self, x: float, trial: int) -> bool: ...
    def respond_with(self, p: float, trial: int) -> bool: ...

class Matcher:
    def __init__(self, target: _Point, *, noise_db: float = 2.0, unsure_band_db: float = 1.0,
                 irregularity_weight: float = 1.0, pitch_min_db: float = -20.0, pitch_max_db: float = 19.7,
                 irregularity_min_db: float = -30.0, irregularity_max_db: float = 5.0, seed: int = 1) -> None: ...
    def distance(self, point: _Point) -> float: ...
    def choose(self, question: MatchQuestion, trial: int) -> str: ...
    def adjust(self, trial: int) -> MatchPoint: ...
    def confidence(self, trial: int) -> int: ...

class Rater:
    def __init__(self, *, scale_min: float = 1.0, scale_max: float = 5.0, distance_scale_db: float = 10.0,
                 noise: float = 0.5, seed: int = 1) -> None: ...
    def expected(self, distance_db: float) -> float: ...
    def rate(self, distance_db: float, trial: int) -> int: ...

def perceptual_target(reference: str, device: str = "tpad") -> MatchPoint: ...

# ------------------------------------------------------------------- store
class Store:
    def __init__(self, path: _Path, mode: Literal["r", "rw"] = "r", journal: Optional[str] = None) -> None: ...
    def close(self) -> None: ...
    closed: bool
    def __enter__(self) -> Store: ...
    def __exit__(self, *exc: Any) -> None: ...
    schema_version: int
    path: str
    def participants(self) -> list[str]: ...
    def sessions(self) -> list[dict[str, Any]]: ...
    def session(self, session_id: int) -> dict[str, Any]: ...
    def session_json(self, session_id: int) -> str: ...
    def trials(self, session_id: int) -> list[dict[str, Any]]: ...
    def rows(self, session_id: Optional[int] = None, *,
             columns: bool = False) -> Union[list[dict[str, Any]], dict[str, npt.NDArray[Any]]]: ...

def read_trials(path: _Path, session_id: Optional[int] = None, *,
                columns: bool = False) -> Union[list[dict[str, Any]], dict[str, npt.NDArray[Any]]]: ...
def trial_columns() -> list[str]: ...
