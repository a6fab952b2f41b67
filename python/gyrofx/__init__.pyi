"""Type stubs of gyrofx's compiled model (see the module docstring and python/README.md).

Codes are two's-complement integers of the named port's format (``s24.14``: signed, 24-bit
word, 14 fraction bits; real value = code · 2^-14); flags are 0/1; a mode is 1 normal, 0
reverse. Real values are °/s. Every refused input raises ``GyrofxError``.
"""

from os import PathLike
from pathlib import Path
from typing import Any, ClassVar, Dict, List, Literal, Optional, Sequence, Tuple, TypedDict, Union, final, overload

import numpy as np
import numpy.typing as npt

__all__ = [
    "Chain",
    "ChainFloat",
    "Estimator",
    "EstimatorFloat",
    "Format",
    "GyroLoop",
    "GyroLoopFloat",
    "GyrofxError",
    "Kf",
    "KfFloat",
    "MeanFilter",
    "MeanFilterFloat",
    "Overflow",
    "Plan",
    "PopulationResult",
    "Resonator",
    "Rounding",
    "Sequencer",
    "System",
    "SystemFloat",
    "__version__",
    "population",
    "quantize",
    "to_real",
]

__version__: str

_Codes = npt.NDArray[np.int64]
_Reals = npt.NDArray[np.float64]
_BandwidthSelect = Union[int, npt.ArrayLike]

# What `step` returns: a dict of the block's output ports, named as ``ports()`` lists them
# (``process``: the same keys, numpy arrays).
class _KfStep(TypedDict):
    out_valid: int
    rate_out: int

class _KfProcess(TypedDict):
    out_valid: _Codes
    rate_out: _Codes

class _KfFloatStep(TypedDict):
    out_valid: int
    rate_out: float

class _KfFloatProcess(TypedDict):
    out_valid: _Codes
    rate_out: _Reals

class _EstimatorStep(TypedDict):
    bias_a: int
    bias_b: int
    estimated: int

class _EstimatorFloatStep(TypedDict):
    bias_a: float
    bias_b: float

class _MeanFilterStep(TypedDict):
    y_valid: int
    y: int
    kept: int

class _MeanFilterFloatStep(TypedDict):
    y_valid: int
    y: float
    kept: int

class _ResonatorStep(TypedDict):
    adc_x: int
    adc_y: int

class GyrofxError(ValueError):
    """A refused config, format or argument; the message is the CLI's."""

@final
class Format:
    """A fixed-point format: ``Format("s24.14")`` or ``Format(width=24, fraction=14)``; equal to
    its string. A code's real value is ``code * lsb``."""

    def __new__(
        cls,
        text: Optional[str] = None,
        *,
        width: Optional[int] = None,
        fraction: Optional[int] = None,
        signed: bool = True,
    ) -> Format: ...
    @property
    def width(self) -> int: ...
    @property
    def fraction(self) -> int: ...
    @property
    def signed(self) -> bool: ...
    @property
    def min_code(self) -> int: ...
    @property
    def max_code(self) -> int: ...
    @property
    def lsb(self) -> float:
        """2^-fraction."""
    def to_real(self, codes: npt.ArrayLike) -> _Reals: ...
    def quantize(
        self,
        values: npt.ArrayLike,
        rounding: Union[Rounding, _RoundingName] = "nearest",
        overflow: Union[Overflow, _OverflowName] = "saturate",
    ) -> _Codes: ...
    def __eq__(self, other: object, /) -> bool: ...
    def __hash__(self) -> int: ...

@final
class Rounding:
    """Rounding of the dropped bits; each has the config's name (``config_name``)."""

    FLOOR: ClassVar[Rounding]
    CEIL: ClassVar[Rounding]
    ZERO: ClassVar[Rounding]
    NEAREST: ClassVar[Rounding]
    ROUND: ClassVar[Rounding]
    CONVERGENT: ClassVar[Rounding]
    @property
    def config_name(self) -> str: ...

@final
class Overflow:
    """What a value outside the format becomes."""

    SATURATE: ClassVar[Overflow]
    WRAP: ClassVar[Overflow]
    @property
    def config_name(self) -> str: ...

_FormatLike = Union[Format, str]
_RoundingName = Literal["floor", "ceil", "zero", "nearest", "round", "convergent"]
_OverflowName = Literal["saturate", "wrap"]

@overload
def quantize(
    values: npt.ArrayLike,
    fmt: _FormatLike,
    rounding: Union[Rounding, _RoundingName] = "nearest",
    overflow: Union[Overflow, _OverflowName] = "saturate",
    *,
    counts: Literal[False] = False,
) -> _Codes:
    """Real values to codes of ``fmt``. rounding: floor, ceil, zero, nearest (ties up),
    round (ties away from zero), convergent (ties to even); overflow: saturate or wrap."""
@overload
def quantize(
    values: npt.ArrayLike,
    fmt: _FormatLike,
    rounding: Union[Rounding, _RoundingName] = "nearest",
    overflow: Union[Overflow, _OverflowName] = "saturate",
    *,
    counts: Literal[True],
) -> Tuple[_Codes, int]:
    """``(codes, overflowed)``: also how many values did not fit ``fmt``."""

def to_real(codes: npt.ArrayLike, fmt: _FormatLike) -> _Reals:
    """Codes of ``fmt`` to real values (code · 2^-frac); codes outside ``fmt`` are refused."""

@final
class Plan:
    """A resolved config: every block's formats, ROMs and designs, as ``gyrofx generate``
    resolves them."""

    @staticmethod
    def default() -> Plan: ...
    @staticmethod
    def preset(name: str) -> Plan:
        """gu2019, xue2015 or mpu6050 over the default."""
    @staticmethod
    def from_toml(text: str, origin: str = "<toml text>") -> Plan:
        """A (partial) config over the default; ``origin`` names it in errors."""
    @staticmethod
    def from_file(path: Union[str, PathLike[str]], preset: Optional[str] = None) -> Plan: ...
    @staticmethod
    def from_package(folder: Union[str, PathLike[str]]) -> Plan:
        """The config a generated package was made from (its manifest.json)."""
    def toml(self) -> str:
        """The whole resolved config (every key)."""
    @property
    def fs_hz(self) -> float: ...
    @property
    def bandwidths_hz(self) -> list[float]:
        """KF bandwidths, Hz, in ROM order (``bw_sel`` indexes them)."""
    def formats(self) -> Dict[str, str]:
        """Every quantization point's format by ``block.signal``, e.g. ``"kf.input": "s24.14"``."""
    def kf(self) -> Kf: ...
    def kf_float(self, ideal: bool = False) -> KfFloat: ...
    def sequencer(self) -> Sequencer: ...
    def estimator(self) -> Estimator: ...
    def estimator_float(self, ideal: bool = False) -> EstimatorFloat: ...
    def mean_filter(self) -> MeanFilter: ...
    def mean_filter_float(self) -> MeanFilterFloat: ...
    def chain(self) -> Chain: ...
    def chain_float(self, ideal: bool = False) -> ChainFloat: ...
    def gyro_loop(self, gyro: str = "a") -> GyroLoop:
        """Gyro "a"'s (the block's vectors) or "b"'s digital loop; its ``latency_clocks`` and
        ``min_clocks_per_sample`` are the folded loop's with ``architecture = "serial"``."""
    def gyro_loop_float(self, gyro: str = "a") -> GyroLoopFloat: ...
    def system(self) -> System:
        """Both loops and the chain (resonator plants only); with ``architecture = "serial"``
        gyrofx_system_serial's timing, its chain outputs ``chain_delay_samples`` later."""
    def system_float(self) -> SystemFloat: ...
    def resonator(self, gyro: str = "a", seed: Optional[int] = None, noise: bool = True) -> Resonator:
        """The simulated resonator; seed defaults to generate's (2·seed, 2·seed + 1)."""

@final
class Kf:
    """The bit-accurate steady-state KF (gyrofx_kf); the RTL shows rate_out latency_clocks after
    the sample's ce and takes a sample at most every min_clocks_per_sample clocks."""

    input_format: str
    output_format: str
    latency_clocks: int
    min_clocks_per_sample: int
    def ports(self) -> List[Tuple[str, str, str]]:
        """``(name, format, direction)`` of each port, as the vector files carry them."""
    def overflow_counts(self) -> Dict[str, int]:
        """Saturations and wraps per quantization point since it was made (a reset keeps them)."""
    def reset(self) -> None: ...
    def step(self, z: int, bw_sel: int = 0) -> _KfStep:
        """One step: ``z`` (input-format code) -> out_valid (1) and rate_out (output-format code)."""
    def process(self, z: npt.ArrayLike, bw_sel: _BandwidthSelect = 0) -> _KfProcess: ...
    def state(self) -> Tuple[int, int]:
        """``(x1, x2)`` as state-format codes."""
    def error_bound_lsb(self, samples: int, switches: int = 0) -> float:
        """Derived bound on |fixed - float twin| in output LSB after ``samples`` steps."""

@final
class KfFloat:
    """The KF's float twin, °/s."""

    def reset(self) -> None: ...
    def step(self, z: float, bw_sel: int = 0) -> _KfFloatStep: ...
    def process(self, z: npt.ArrayLike, bw_sel: _BandwidthSelect = 0) -> _KfFloatProcess: ...

@final
class Sequencer:
    """The mode-reversal sequencer (gyrofx_sequencer): combinational slot outputs per clock."""

    latency_clocks: int
    min_clocks_per_sample: int
    def ports(self) -> List[Tuple[str, str, str]]:
        """``(name, format, direction)`` of each port, as the vector files carry them."""
    def overflow_counts(self) -> Dict[str, int]:
        """Saturations and wraps per quantization point since it was made (a reset keeps them)."""
    def reset(self) -> None: ...
    def step(self) -> Dict[str, int]:
        """mode_a, mode_b, blank_a, blank_b, interval_a, interval_b, done_a, done_b,
        window_done of this clock; then advances."""
    def process(self, samples: int) -> Dict[str, _Codes]: ...

@final
class Estimator:
    """The least-squares bias estimator (gyrofx_bias_estimator)."""

    latency_clocks: int
    min_clocks_per_sample: int
    def ports(self) -> List[Tuple[str, str, str]]:
        """``(name, format, direction)`` of each port, as the vector files carry them."""
    def overflow_counts(self) -> Dict[str, int]:
        """Saturations and wraps per quantization point since it was made (a reset keeps them)."""
    input_format: str
    bias_format: str
    def reset(self) -> None: ...
    def step(
        self,
        y_a: int,
        y_b: int,
        blank_a: int,
        blank_b: int,
        done_a: int,
        done_b: int,
        interval_a: int,
        interval_b: int,
        window_done: int,
    ) -> _EstimatorStep:
        """bias_a, bias_b, estimated after the clock."""
    def process(
        self,
        y_a: npt.ArrayLike,
        y_b: npt.ArrayLike,
        blank_a: npt.ArrayLike,
        blank_b: npt.ArrayLike,
        done_a: npt.ArrayLike,
        done_b: npt.ArrayLike,
        interval_a: npt.ArrayLike,
        interval_b: npt.ArrayLike,
        window_done: npt.ArrayLike,
    ) -> Dict[str, _Codes]: ...

@final
class EstimatorFloat:
    """The estimator's float twin, °/s."""

    def reset(self) -> None: ...
    def step(
        self,
        y_a: float,
        y_b: float,
        blank_a: int,
        blank_b: int,
        done_a: int,
        done_b: int,
        interval_a: int,
        interval_b: int,
        window_done: int,
    ) -> _EstimatorFloatStep: ...

@final
class MeanFilter:
    """The mean filter with gross-error rejection (gyrofx_mean_filter)."""

    latency_clocks: int
    min_clocks_per_sample: int
    def ports(self) -> List[Tuple[str, str, str]]:
        """``(name, format, direction)`` of each port, as the vector files carry them."""
    def overflow_counts(self) -> Dict[str, int]:
        """Saturations and wraps per quantization point since it was made (a reset keeps them)."""
    window: int
    input_format: str
    output_format: str
    def reset(self) -> None: ...
    def step(self, x: int) -> _MeanFilterStep:
        """y_valid (1 on a block's last sample), y, kept (0 where y_valid is 0)."""
    def process(self, x: npt.ArrayLike) -> Dict[str, _Codes]:
        """y_valid, y, kept per input sample (y and kept 0 where y_valid is 0)."""

@final
class MeanFilterFloat:
    """The mean filter's float twin, °/s."""

    def reset(self) -> None: ...
    def step(self, x: float) -> _MeanFilterFloatStep: ...

@final
class Chain:
    """The whole chain (gyrofx_top): sequencer, estimator, calibration and KF."""

    latency_clocks: int
    min_clocks_per_sample: int
    def ports(self) -> List[Tuple[str, str, str]]:
        """``(name, format, direction)`` of each port, as the vector files carry them."""
    def overflow_counts(self) -> Dict[str, int]:
        """Saturations and wraps per quantization point since it was made (a reset keeps them)."""
    def reset(self) -> None: ...
    def next_modes(self) -> Tuple[int, int]:
        """The modes the next step runs in (what a plant needs first)."""
    def step(self, y_a: int, y_b: int, bw_sel: int = 0) -> Dict[str, int]:
        """mode_a, mode_b, out_valid, rate_out, bias_a, bias_b, estimated."""
    def process(
        self, y_a: npt.ArrayLike, y_b: npt.ArrayLike, bw_sel: _BandwidthSelect = 0
    ) -> Dict[str, _Codes]: ...

@final
class ChainFloat:
    """The chain's float twin, °/s."""

    def reset(self) -> None: ...
    def step(self, y_a: float, y_b: float, bw_sel: int = 0) -> Dict[str, Optional[float]]:
        """out_valid, rate_out (None when the KF did not step), bias_a, bias_b."""

_PerSample = Union[int, npt.ArrayLike]

@final
class GyroLoop:
    """One gyro's digital loop (gyrofx_gyro_loop), one step per ADC sample: ADC codes of both
    axes and the mode (1 normal, 0 reverse) in; DAC codes, locked, and every decimation-th
    sample the rate and quadrature (°/s codes, held between out_valid pulses) out."""

    latency_clocks: int
    min_clocks_per_sample: int
    def ports(self) -> List[Tuple[str, str, str]]:
        """``(name, format, direction)`` of each port, as the vector files carry them."""
    def overflow_counts(self) -> Dict[str, int]:
        """Saturations and wraps per quantization point since it was made (a reset keeps them)."""
    adc_rate_hz: float
    decimation: int
    adc_format: str
    dac_format: str
    output_format: str
    def reset(self) -> None: ...
    def step(self, adc_x: int, adc_y: int, mode: int = 1) -> Dict[str, int]:
        """dac_x, dac_y, locked, out_valid, rate, quadrature."""
    def process(
        self, adc_x: npt.ArrayLike, adc_y: npt.ArrayLike, mode: _PerSample = 1
    ) -> Dict[str, _Codes]: ...

@final
class GyroLoopFloat:
    """The loop's float twin: ADC in full-scale units, DAC in LSB (unquantized), rate in °/s."""

    def reset(self) -> None: ...
    def step(self, adc_x: float, adc_y: float, mode: int = 1) -> Dict[str, Optional[float]]:
        """dac_x, dac_y, locked, out_valid, rate and quadrature (None between outputs)."""

@final
class System:
    """The whole gyro at the ADC rate (gyrofx_system): both loops and the chain, whose
    sequencer commands the loops' modes. enable 0 holds the chain (start-up)."""

    latency_clocks: int
    min_clocks_per_sample: int
    def ports(self) -> List[Tuple[str, str, str]]:
        """``(name, format, direction)`` of each port, as the vector files carry them."""
    def overflow_counts(self) -> Dict[str, int]:
        """Saturations and wraps per quantization point since it was made (a reset keeps them)."""
    decimation: int
    window: int
    chain_delay_samples: int
    """ADC samples by which out_valid, rate_out, bias_a, bias_b and estimated come after the
    sample that produced them: 0, or gyrofx_system_serial's CHAIN_DELAY_SAMPLES."""
    def reset(self) -> None: ...
    def next_modes(self) -> Tuple[int, int]:
        """The modes the loops take at the next step if enable is 1."""
    def step(
        self, adc_a_x: int, adc_a_y: int, adc_b_x: int, adc_b_y: int, enable: int = 1, bw_sel: int = 0
    ) -> Dict[str, int]:
        """dac_a_x, dac_a_y, dac_b_x, dac_b_y, locked_a, locked_b, mode_a, mode_b (the next
        sample's), out_valid, rate_out (held), bias_a, bias_b, estimated."""
    def process(
        self,
        adc_a_x: npt.ArrayLike,
        adc_a_y: npt.ArrayLike,
        adc_b_x: npt.ArrayLike,
        adc_b_y: npt.ArrayLike,
        enable: _PerSample = 1,
        bw_sel: _BandwidthSelect = 0,
    ) -> Dict[str, _Codes]: ...

@final
class SystemFloat:
    """The system's float twin: ADC in full-scale units, DAC in LSB, rates and biases in °/s."""

    def reset(self) -> None: ...
    def next_modes(self) -> Tuple[int, int]: ...
    def step(
        self, adc_a_x: float, adc_a_y: float, adc_b_x: float, adc_b_y: float, enable: int = 1, bw_sel: int = 0
    ) -> Dict[str, Optional[float]]:
        """dac_*, locked_*, mode_a, mode_b, out_valid, and rate_out, bias_a, bias_b (None
        where the chain gave none)."""

@final
class Resonator:
    """A simulated resonator with its front end: DAC codes in, the next ADC codes out."""

    sample_rate_hz: float
    adc_saturations: int
    def set_rate_dps(self, rate_dps: float) -> None: ...
    def set_mode(self, mode: int) -> None:
        """The pick-offs follow the loop's mode (1 normal, 0 reverse) from this sample on."""
    def step(self, dac_x: int, dac_y: int) -> _ResonatorStep:
        """The ADC codes adc_x, adc_y the loop reads next."""

class PopulationResult:
    """A population study's outcome: ``population.csv`` and ``summary.json`` as ``gyrofx
    population`` writes them, byte for byte. ``header`` and ``lines`` are the CSV's lines
    (each ends in a newline; ``lines[i]`` is member ``i``), ``columns`` the header's names,
    ``summary`` the parsed ``summary.json`` and ``summary_json`` its exact text."""

    columns: List[str]
    header: str
    lines: List[str]
    summary: Dict[str, Any]
    summary_json: str
    def __init__(
        self,
        columns: List[str],
        header: str,
        lines: List[str],
        summary: Dict[str, Any],
        summary_json: str,
    ) -> None: ...
    @property
    def csv(self) -> str:
        """``population.csv``'s text."""
    def rows(self) -> List[Dict[str, str]]:
        """Each member's row as a dict of cells by column (empty: the figure does not exist)."""
    def write(self, folder: Union[str, PathLike[str]]) -> List[Path]:
        """Writes ``population.csv`` and ``summary.json`` (the CLI's bytes; not its plots or
        manifest) into ``folder``, created if missing; returns their paths."""

def population(
    config: Union[str, PathLike[str], None] = None,
    *,
    toml: Optional[str] = None,
    preset: Optional[str] = None,
    gyros: int,
    seconds: float = 10.0,
    noise: bool = False,
    seed: Optional[int] = None,
    targets: Sequence[str] = (),
    client: Any = None,
    batch: Optional[int] = None,
    jobs: Optional[int] = None,
    in_flight: Optional[int] = None,
) -> PopulationResult:
    """``gyrofx population``'s study (docs/guide how-to/population.md): the default config
    overlaid by ``preset``, then the file ``config`` or the TOML text ``toml``; ``gyros``
    members, ``seconds`` of chain run each, ``noise``, ``seed`` and ``targets`` as the CLI's
    flags. Without ``client``, on ``jobs`` threads here (default: every core); with a
    ``dask.distributed.Client``, on its cluster in batches of ``batch`` members, at most
    ``in_flight`` batches out (default: twice its threads), only strings and numbers shipped.
    Equal to the CLI's files byte for byte either way."""
