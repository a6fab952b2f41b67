"""``gyrofx.population``: the study ``gyrofx population`` runs, here or on a dask cluster.

A member's row and figures are a pure function of the run's definition (the config's text,
where it came from, the preset, the seed, the seconds, the noise) and its index: the compiled
``_population_members`` computes a batch of them from those strings and numbers alone. So a
batch runs wherever ``gyrofx`` is installed (a thread here, a ``dask.distributed`` worker) and
nothing but strings, integers and floats crosses the wire; the rows are put back in member
order and the summary is the CLI's, so ``population.csv`` and ``summary.json`` equal the CLI's
byte for byte.
"""

from __future__ import annotations

import collections
import concurrent.futures
import json
import os
import pathlib
from typing import Any, Dict, Iterable, Iterator, List, Optional, Sequence, Tuple, Union

# The compiled module's stubs are __init__.pyi, which leaves out these private functions: mypy
# (and so stubtest, which reads this file as its own stub) takes them as untyped.
from ._gyrofx import (  # type: ignore[import-not-found]
    GyrofxError,
    _population_describe,
    _population_members,
    _population_summary,
)

#: Most members, as ``gyrofx population --gyros``.
MAX_MEMBERS = 10_000_000

# (config text, origin, preset, seed, seconds, noise): all a batch needs, picklable as is.
_Definition = Tuple[Optional[str], str, Optional[str], int, float, bool]
# (member index, CSV line, status, figures)
_Member = Tuple[int, str, str, List[Optional[float]]]


def _study_batch(definition: _Definition, first: int, count: int) -> List[_Member]:
    """Members ``first .. first + count`` of the run ``definition``: what a worker runs.

    Module level and given only strings and numbers, so that ``dask.distributed`` ships it by
    reference (the worker imports ``gyrofx``) with arguments pickled as plain data.
    """
    config, origin, preset, seed, seconds, noise = definition
    return _population_members(config, origin, preset, seed, first, count, seconds, noise)


class PopulationResult:
    """A population study's outcome: ``population.csv`` and ``summary.json`` as the CLI writes them.

    ``header`` and ``lines`` are the CSV's lines (each ends in a newline; ``lines[i]`` is
    member ``i``), ``columns`` the header's names, ``summary`` the parsed ``summary.json`` and
    ``summary_json`` its exact text.
    """

    def __init__(
        self,
        columns: List[str],
        header: str,
        lines: List[str],
        summary: Dict[str, Any],
        summary_json: str,
    ) -> None:
        self.columns = columns
        self.header = header
        self.lines = lines
        self.summary = summary
        self.summary_json = summary_json

    def __repr__(self) -> str:
        return f"PopulationResult({len(self.lines)} members, {len(self.columns)} columns)"

    @property
    def csv(self) -> str:
        """``population.csv``'s text."""
        return self.header + "".join(self.lines)

    def rows(self) -> List[Dict[str, str]]:
        """Each member's row as a dict of cells by column (empty: the figure does not exist)."""
        import csv

        return list(csv.DictReader([self.header, *self.lines]))

    def write(self, folder: Union[str, os.PathLike[str]]) -> List[pathlib.Path]:
        """Writes ``population.csv`` and ``summary.json`` into ``folder`` (created if missing).

        Their bytes are the CLI's for the same run; the plots and ``manifest.json`` of
        ``gyrofx population`` are not written. Returns the two paths.
        """
        out = pathlib.Path(folder)
        out.mkdir(parents=True, exist_ok=True)
        csv_path = out / "population.csv"
        with open(csv_path, "w", encoding="utf-8", newline="") as f:
            f.write(self.header)
            f.writelines(self.lines)
        summary_path = out / "summary.json"
        with open(summary_path, "w", encoding="utf-8", newline="") as f:
            f.write(self.summary_json)
        return [csv_path, summary_path]


def _batches(members: int, batch: int) -> Iterator[Tuple[int, int]]:
    for first in range(0, members, batch):
        yield first, min(batch, members - first)


def _in_order(
    done: Iterable[Tuple[int, List[_Member]]], expected: int
) -> Iterator[List[_Member]]:
    """Batches given as ``(first, members)`` in any order, yielded in member order."""
    waiting: Dict[int, List[_Member]] = {}
    next_first = 0
    for first, members in done:
        waiting[first] = members
        while next_first in waiting:
            ready = waiting.pop(next_first)
            next_first += len(ready)
            yield ready
    if next_first != expected:
        raise RuntimeError(f"{next_first} of {expected} members came back")


def _run_local(
    definition: _Definition, members: int, batch: int, jobs: int
) -> Iterator[List[_Member]]:
    """Batches on ``jobs`` threads (the compiled study releases the GIL), at most ``2·jobs``
    batches submitted and not yet yielded."""
    if jobs == 1:
        for first, count in _batches(members, batch):
            yield _study_batch(definition, first, count)
        return
    window = 2 * jobs
    with concurrent.futures.ThreadPoolExecutor(max_workers=jobs) as pool:
        pending: collections.deque[concurrent.futures.Future[List[_Member]]] = collections.deque()
        batches = _batches(members, batch)
        for first, count in batches:
            pending.append(pool.submit(_study_batch, definition, first, count))
            if len(pending) >= window:
                break
        while pending:
            done = pending.popleft().result()
            for first, count in batches:
                pending.append(pool.submit(_study_batch, definition, first, count))
                break
            yield done


def _cluster_threads(client: Any) -> int:
    """The threads of the cluster's workers now (at least 1)."""
    return max(1, sum(client.nthreads().values()))


def _run_on_client(
    client: Any, definition: _Definition, members: int, batch: int, in_flight: Optional[int]
) -> Iterator[List[_Member]]:
    """Batches on a ``dask.distributed`` client: ``client.submit`` of :func:`_study_batch`
    with plain arguments, at most ``in_flight`` batches submitted and not yet yielded
    (default: twice the cluster's threads, read again as batches come back, so that workers
    joining later, as ``dask-jobqueue``'s do, get work), taken as they complete and yielded in
    order."""
    from distributed import as_completed

    batches = _batches(members, batch)
    firsts: Dict[Any, int] = {}
    completed = as_completed()
    outstanding = 0

    def fill() -> None:
        nonlocal outstanding
        window = in_flight if in_flight is not None else 2 * _cluster_threads(client)
        while outstanding < window:
            work = next(batches, None)
            if work is None:
                return
            future = client.submit(_study_batch, definition, *work)
            firsts[future.key] = work[0]
            completed.add(future)
            outstanding += 1

    def finished() -> Iterator[Tuple[int, List[_Member]]]:
        for future in completed:
            first = firsts.pop(future.key)
            result = future.result()
            future.release()
            yield first, result

    fill()
    # A batch counts against the window from its submission until it is yielded in order.
    for ready in _in_order(finished(), members):
        yield ready
        outstanding -= 1
        fill()


def population(
    config: Union[str, os.PathLike[str], None] = None,
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
    """Runs ``gyrofx population``'s study: ``gyros`` members drawn from the ``[population]``
    spreads, each through its loops and the chain for ``seconds`` s after the 0.5 s start-up.

    The config is the embedded default, overlaid by ``preset``, then by the file ``config``
    (as ``--config``; errors name it by the path given) or the TOML text ``toml``. ``seed``
    replaces the config's; ``noise`` and ``targets`` (``"residual_dps<=0.01"``) as
    ``--noise`` and ``--target``.

    Without ``client`` the members run here on ``jobs`` threads (default: every core). With a
    ``dask.distributed.Client`` they run on its cluster: batches of ``batch`` members
    (default: about four batches per worker thread, at most 64 members) are submitted as
    :func:`_study_batch` with the run's definition as plain strings and numbers, at most
    ``in_flight`` batches (default: twice the cluster's threads) submitted and not yet taken
    back, taken as they complete and put in member order. The workers need ``gyrofx``
    installed (the same version). Either way the result equals the CLI's ``population.csv``
    and ``summary.json`` byte for byte.

    Raises ``GyrofxError`` for a refused config (the CLI's message), preset, seconds, target
    or member count; ``OSError`` when the ``config`` file cannot be read.
    """
    if config is not None and toml is not None:
        raise GyrofxError("give config (a file) or toml (a text), not both")
    if isinstance(gyros, bool) or not isinstance(gyros, int) or not 1 <= gyros <= MAX_MEMBERS:
        raise GyrofxError(f"gyros {gyros!r} is not allowed: 1..={MAX_MEMBERS}")
    for name, value in (("batch", batch), ("jobs", jobs), ("in_flight", in_flight)):
        whole = isinstance(value, int) and not isinstance(value, bool)
        if value is not None and not (whole and value >= 1):
            raise GyrofxError(f"{name} {value!r} is not allowed: a whole number >= 1")
    if isinstance(targets, str):
        targets = [targets]
    targets = [str(t) for t in targets]
    text: Optional[str]
    if config is not None:
        origin = os.fspath(config)
        with open(config, encoding="utf-8") as f:
            text = f.read()
    else:
        origin, text = "<toml text>", toml
    seconds = float(seconds)
    noise = bool(noise)
    described = _population_describe(text, origin, preset, seed, seconds, noise, targets)
    definition: _Definition = (text, origin, preset, described["seed"], seconds, noise)
    if client is None:
        threads = jobs or os.cpu_count() or 1
        size = batch or 1
        batches = _run_local(definition, gyros, size, threads)
    else:
        if batch is None:
            batch = max(1, min(64, gyros // (4 * _cluster_threads(client))))
        batches = _run_on_client(client, definition, gyros, batch, in_flight)
    lines: List[str] = []
    records: List[Tuple[str, List[Optional[float]]]] = []
    for members in batches:
        for index, line, status, figures in members:
            if index != len(lines):
                raise RuntimeError(f"member {index} came back in place of {len(lines)}")
            lines.append(line)
            records.append((status, figures))
    summary_json = _population_summary(
        text, origin, preset, described["seed"], seconds, noise, targets, records
    )
    return PopulationResult(
        columns=list(described["columns"]),
        header=described["header"],
        lines=lines,
        summary=json.loads(summary_json),
        summary_json=summary_json,
    )
