"""Sweeps: one scene run for each value (or grid point) of scene parameters, on Dask.

Every variant is validated first (a bad value fails before any work). The variants'
plans are compared by stage key: a stage with the same key in several variants (the
FE condensation when only mu changes, the virgin curve when only the structure
changes) is *shared* and runs once, in dependency waves of one task per distinct key;
then every variant runs as one task, reading the shared results from the cache that
all workers use. Results are gathered into one table (CSV and JSON) and a plot.

A variant that fails while it runs (or whose shared stage failed) does not stop the
others: its row holds the message in the ``error`` column (None for the others) and
the table is still written; ``fail_fast`` stops at the first failure instead.

The scheduler is a Dask local cluster (one single-threaded worker process per core by
default), an existing cluster (``scheduler`` address), or none (``serial``: the same
tasks in this process, the reference the tests compare against).
"""
from __future__ import annotations

import csv
import io
import itertools
import json
import math
import os
from dataclasses import dataclass, field
from pathlib import Path

from damper.cache import Store
from damper.cli.common import atomic_write, dumps
from damper.limits import MAX_SWEEP_VARIANTS
from damper.run.graph import closure
from damper.tasks import executor


@dataclass
class SweepRecord:
    """The outcome of a sweep."""

    params: list
    rows: list = field(default_factory=list)
    computations: dict = field(default_factory=dict)   # stage key -> {"stage": name, "count": times computed}
    shared: list = field(default_factory=list)         # names of the shared stages (first variant)
    outputs: dict = field(default_factory=dict)

    def to_json(self) -> dict:
        return {"params": self.params, "rows": self.rows, "shared_stages": self.shared,
                "computations": self.computations, "outputs": self.outputs}


def variants(specs: list[tuple[str, list]], grid: bool = True) -> list[dict]:
    """Overrides per variant: the Cartesian product of the parameters' values (``grid``)
    or their values taken in step (``zip``, equal lengths)."""
    names = [n for n, _ in specs]
    lists = [v for _, v in specs]
    if not specs:
        raise ValueError("a sweep needs at least one --param with --values or --range")
    if len(set(names)) != len(names):
        raise ValueError(f"a parameter is given twice: {names}")
    if not grid and len({len(v) for v in lists}) > 1:
        raise ValueError("--zip needs the same number of values for every parameter")
    count = math.prod(len(v) for v in lists) if grid else len(lists[0])
    if count > MAX_SWEEP_VARIANTS:
        raise ValueError(f"the sweep has {count} variants, above the limit {MAX_SWEEP_VARIANTS}: each variant "
                         "is one scene run (seconds to minutes); sweep fewer values")
    combos = itertools.product(*lists) if grid else zip(*lists)
    return [dict(zip(names, c)) for c in combos]


def _restricted_plan(text, source, overrides, store, only):
    from damper.run.runner import plan_scene
    from damper.scene import parse_scene

    scene = parse_scene(text, source, overrides, base=Path(source).parent)
    plan = plan_scene(scene, store)
    if only is not None:
        keep = closure(set(only), plan)
        for s in plan.stages:
            if s.name not in keep and s.action != "skip":
                s.action, s.reason = "skip", "not in this sweep task"
    return scene, plan


def run_task(text: str, source: str, overrides: dict, folder: str, max_bytes: int,
             only: list | None = None) -> dict:
    """Run one variant (or only the stages ``only`` and their dependencies) against the
    cache ``folder``; return the computed stage keys and the stages' headline numbers."""
    from damper.run.progress import Progress
    from damper.run.runner import execute

    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    store = Store(folder, max_bytes)
    scene, plan = _restricted_plan(text, source, overrides, store, only)
    quiet = io.StringIO()
    rec = execute(scene, plan, store, None, Progress(0, stream=quiet, live=False, out=quiet))
    scalars = {}
    for s in plan.stages:
        if s.name in rec.results:
            for k, v in s.kind.scalars(s, rec.results[s.name]).items():
                scalars[f"{s.name}.{k}"] = v
    return {"computed": [(s.name, s.key) for s in plan.stages if s.action == "compute"], "scalars": scalars}


def run_task_or_error(*args, **kwargs) -> dict:
    """:func:`run_task`, with a failure returned as ``{"error": message}`` (the sweep goes on)."""
    try:
        return run_task(*args, **kwargs)
    except Exception as err:  # noqa: BLE001 - the failure becomes the variant's row
        kind = "" if isinstance(err, (ValueError, RuntimeError, OSError)) else f"{type(err).__name__}: "
        return {"error": f"{kind}{' '.join(str(err).split())}", "computed": [], "scalars": {}}


def run_sweep(scene_path, specs, store: Store, out: Path | None = None, grid: bool = True,
              scheduler: str | None = None, workers: int | None = None, serial: bool = False,
              echo=print, fail_fast: bool = False) -> SweepRecord:
    """Run the sweep of ``specs`` ([(dotted parameter, values)]) over the scene file.

    Each row holds the variant's parameters, its stages' headline numbers and ``error``
    (None, or why the variant failed); ``fail_fast`` raises the first failure instead.
    """
    from damper.scene import parse_scene
    from damper.scene.load import read_scene_text

    source = str(scene_path)
    text = read_scene_text(scene_path)
    combos = variants(specs, grid)
    for ov in combos:             # validate every variant before any work
        parse_scene(text, source, ov, base=Path(source).parent)
    task = run_task if fail_fast else run_task_or_error
    rec = SweepRecord([n for n, _ in specs])
    plans = [_restricted_plan(text, source, ov, store, None)[1] for ov in combos]
    count: dict[str, int] = {}
    for plan in plans:
        for s in plan.stages:
            if s.key and s.action != "skip":
                count[s.key] = count.get(s.key, 0) + 1
    shared = {s.key: (i, s.name) for i, plan in reversed(list(enumerate(plans))) for s in plan.stages
              if count.get(s.key, 0) > 1}
    rec.shared = sorted({name for _, name in shared.values()})
    submit, gather, close = executor(scheduler, workers, serial)
    failed: dict[str, str] = {}                  # shared stage key -> its error
    try:
        waves = _waves(plans, shared)
        for n, wave in enumerate(waves, start=1):
            wave = [(i, name) for i, name in wave if not _failed_dep(plans[i], name, failed)]
            echo(f"sweep: shared wave {n}: {', '.join(name for _, name in wave)}")
            futures = [submit(task, text, source, combos[i], str(store.folder), store.max_bytes, [name])
                       for i, name in wave]
            for (i, name), r in zip(wave, gather(futures)):
                _tally(rec, r)
                if r.get("error"):
                    failed[plans[i][name].key] = f"shared stage {name}: {r['error']}"
        echo(f"sweep: {len(combos)} variants on {'this process' if serial else 'Dask'}")
        blocked = {i: _failed_in(plan, failed) for i, plan in enumerate(plans)}
        todo = [i for i in range(len(combos)) if not blocked[i]]
        futures = [submit(task, text, source, combos[i], str(store.folder), store.max_bytes) for i in todo]
        results = dict(zip(todo, gather(futures)))
        for i, ov in enumerate(combos):
            r = results.get(i) or {"error": blocked[i], "computed": [], "scalars": {}}
            _tally(rec, r)
            rec.rows.append(ov | r["scalars"] | {"error": r.get("error")})
    finally:
        close()
    if out is not None:
        write_table(rec, Path(out))
    return rec


def _failed_dep(plan, name: str, failed: dict) -> bool:
    """Whether a stage depends (directly or not) on a failed shared stage."""
    return any(plan[n].key in failed for n in closure({name}, plan) if n != name)


def _failed_in(plan, failed: dict) -> str | None:
    """The error of a failed shared stage the variant's plan runs, or None."""
    for s in plan.stages:
        if s.action != "skip" and s.key in failed:
            return failed[s.key]
    return None


def _tally(rec: SweepRecord, r: dict) -> None:
    for name, key in r["computed"]:
        entry = rec.computations.setdefault(key, {"stage": name, "count": 0})
        entry["count"] += 1


def _waves(plans, shared) -> list[list[tuple[int, str]]]:
    """Shared stages that need computing, in waves whose dependencies are in earlier waves."""
    todo = {}
    for key, (i, name) in shared.items():
        if plans[i][name].action == "compute":
            todo[key] = (i, name)
    done, waves = set(), []
    while todo:
        wave = [(k, v) for k, v in todo.items()
                if all(plans[v[0]][d].key in done or plans[v[0]][d].key not in todo for d in plans[v[0]][v[1]].deps)]
        waves.append([v for _, v in wave])
        for k, _ in wave:
            done.add(k)
            del todo[k]
    return waves


def write_table(rec: SweepRecord, out: Path) -> None:
    """``sweep.csv``, ``sweep.json`` and ``sweep.png`` (each column against the first parameter)."""
    cols = list(rec.params) + sorted({k for r in rec.rows for k in r if k not in rec.params and k != "error"})
    cols.append("error")
    buf = io.StringIO()
    w = csv.DictWriter(buf, fieldnames=cols)
    w.writeheader()
    for r in rec.rows:
        w.writerow({k: r.get(k) for k in cols})
    rec.outputs["csv"] = str(atomic_write(out / "sweep.csv", buf.getvalue()))
    rec.outputs["json"] = str(out / "sweep.json")
    rec.outputs["plot"] = str(_plot(rec, cols, out / "sweep.png"))
    atomic_write(out / "sweep.json", dumps(rec.to_json(), indent=1) + "\n")


def _plot(rec, cols, path: Path) -> Path:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    x = rec.params[0]
    rows = [r for r in rec.rows if not r.get("error")]   # failed variants have no numbers
    ys = [c for c in cols if c not in rec.params and rows and all(isinstance(r.get(c), (int, float)) for r in rows)
          and len({r.get(c) for r in rows}) > 1][:6]
    fig, axes = plt.subplots(max(len(ys), 1), 1, figsize=(6, 2.2 * max(len(ys), 1)), squeeze=False)
    for ax, c in zip(axes[:, 0], ys):
        groups = {}
        for r in rows:
            groups.setdefault(tuple(r[p] for p in rec.params[1:]), []).append((r[x], r[c]))
        for g, pts in groups.items():
            pts.sort()
            ax.plot(*zip(*pts), "o-", label=", ".join(f"{p}={v}" for p, v in zip(rec.params[1:], g)) or None)
        ax.set(xlabel=x, ylabel=c.split(".", 1)[-1])
        ax.set_title(c.split(".", 1)[0], fontsize=9)
        if len(groups) > 1:
            ax.legend(fontsize=7)
    fig.tight_layout()
    buf = io.BytesIO()
    fig.savefig(buf, format="png", dpi=100)
    plt.close(fig)
    return atomic_write(path, buf.getvalue())


def parse_value(text: str):
    """A command-line value as the scene would hold it: integer, number, true/false or string."""
    try:
        return json.loads(text)
    except ValueError:
        return text
