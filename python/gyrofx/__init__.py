"""gyrofx: the bit-accurate fixed-point model of a MEMS-gyro FPGA signal chain, for Python.

Every class calls the same Rust model that ``gyrofx generate`` writes vectors from, so a
result here equals the vectors and the reference RTL bit for bit. Codes are Python ``int``
or ``numpy.int64`` exactly as the RTL ports carry them; real values are °/s.

    >>> import gyrofx
    >>> plan = gyrofx.Plan.default()
    >>> kf = plan.kf()
    >>> fmt = gyrofx.Format(plan.formats()["kf.input"])
    >>> fmt, fmt.width, fmt.fraction, fmt.max_code, fmt.lsb
    (Format('s24.14'), 24, 14, 8388607, 6.103515625e-05)
    >>> z = gyrofx.quantize([0.5, 0.25], fmt)
    >>> gyrofx.quantize([1e9, 0.5], fmt, gyrofx.Rounding.FLOOR, "saturate", counts=True)
    (array([8388607,    8192]), 1)
    >>> out = kf.process(z)
    >>> sorted(out)
    ['out_valid', 'rate_out']
    >>> kf.reset()
    >>> kf.step(int(z[0]))["rate_out"] == int(out["rate_out"][0])
    True
"""

from ._gyrofx import (
    Chain,
    ChainFloat,
    Estimator,
    EstimatorFloat,
    Format,
    GyroLoop,
    GyroLoopFloat,
    GyrofxError,
    Kf,
    KfFloat,
    MeanFilter,
    MeanFilterFloat,
    Overflow,
    Plan,
    Resonator,
    Rounding,
    Sequencer,
    System,
    SystemFloat,
    __version__,
    quantize,
    to_real,
)
from ._population import PopulationResult, population

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
