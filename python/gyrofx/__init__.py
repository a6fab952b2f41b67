"""gyrofx: the bit-accurate fixed-point model of a MEMS-gyro FPGA signal chain, for Python.

Every class calls the same Rust model that ``gyrofx generate`` writes vectors from, so a
result here equals the vectors and the reference RTL bit for bit. Codes are Python ``int``
or ``numpy.int64`` exactly as the RTL ports carry them; real values are °/s.

    >>> import gyrofx
    >>> plan = gyrofx.Plan.default()
    >>> kf = plan.kf()
    >>> z = gyrofx.quantize([0.5, 0.25], plan.formats()["kf.input"])
    >>> rate = kf.process(z)
"""

from ._gyrofx import (
    Chain,
    ChainFloat,
    Estimator,
    EstimatorFloat,
    GyroLoop,
    GyroLoopFloat,
    GyrofxError,
    Kf,
    KfFloat,
    MeanFilter,
    MeanFilterFloat,
    Plan,
    Resonator,
    Sequencer,
    System,
    SystemFloat,
    __version__,
    quantize,
    to_real,
)

__all__ = [
    "Chain",
    "ChainFloat",
    "Estimator",
    "EstimatorFloat",
    "GyroLoop",
    "GyroLoopFloat",
    "GyrofxError",
    "Kf",
    "KfFloat",
    "MeanFilter",
    "MeanFilterFloat",
    "Plan",
    "Resonator",
    "Sequencer",
    "System",
    "SystemFloat",
    "__version__",
    "quantize",
    "to_real",
]
