"""Sweeps: one scene run for each value (or grid point) of scene parameters, on Dask.

Every variant is validated first (a bad value fails before any work). The variants'
plans are compared by stage key: a stage with the same key in several variants (the
FE condensation when only mu changes, the virgin curve when only the structure
changes) is *shared* and runs once, in dependency waves of one task per distinct key;
then every variant runs as one task, reading the shared results from the cache that
all workers use. Results are gathered into one table (CSV and JSON) and a plot.

The scheduler is a Dask local cluster (one single-threaded worker process per core by
default), an existing cluster (``scheduler`` address), or none (``serial``: the same
tasks in this process, the reference the tests compare against).
"""
from __future__ import annotations

import csv
import io
import itertools
import json
import os
from dataclasses import dataclass, field
from pathlib import Path

from damper.cache import Store
from damper.cli.common import atomic_write, dumps
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
    combos = itertools.product(*lists) if grid else zip(*lists)
    return [dict(zip(names, c)) for c in combos]


def _restricted_plan(text, source, overrides, store, only):
    from damper.run.runner import plan_scene
    from damper.scene import parse_scene

    scene = parse_scene(text, source, overrides)
    plan = plan_scene(scene, store)
    if only is not None:
        keep = _closure(plan, set(only))
        for s in plan.stages:
            if s.name not in keep and s.action != "skip":
                s.action, s.reason = "skip", "not in this sweep task"
    return scene, plan


def _closure(plan, names):
    out, todo = set(), list(names)
    while todo:
        n = todo.pop()
        if n not in out:
            out.add(n)
            todo.extend(plan[n].deps)
    return out


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


def run_sweep(scene_path, specs, store: Store, out: Path | None = None, grid: bool = True,
              scheduler: str | None = None, workers: int | None = None, serial: bool = False,
              echo=print) -> SweepRecord:
    """Run the sweep of ``specs`` ([(dotted parameter, values)]) over the scene file."""
    from damper.scene import parse_scene

    text = Path(scene_path).read_text()
    source = str(scene_path)
    combos = variants(specs, grid)
    for ov in combos:             # validate every variant before any work
        parse_scene(text, source, ov)
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
    try:
        waves = _waves(plans, shared)
        for n, wave in enumerate(waves, start=1):
            echo(f"sweep: shared wave {n}: {', '.join(name for _, name in wave)}")
            futures = [submit(run_task, text, source, combos[i], str(store.folder), store.max_bytes, [name])
                       for i, name in wave]
            for r in gather(futures):
                _tally(rec, r)
        echo(f"sweep: {len(combos)} variants on {'this process' if serial else 'Dask'}")
        futures = [submit(run_task, text, source, ov, str(store.folder), store.max_bytes) for ov in combos]
        for ov, r in zip(combos, gather(futures)):
            _tally(rec, r)
            rec.rows.append(ov | r["scalars"])
    finally:
        close()
    if out is not None:
        write_table(rec, Path(out))
    return rec


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
    cols = list(rec.params) + sorted({k for r in rec.rows for k in r if k not in rec.params})
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
    ys = [c for c in cols if c not in rec.params and all(isinstance(r.get(c), (int, float)) for r in rec.rows)
          and len({r.get(c) for r in rec.rows}) > 1][:6]
    fig, axes = plt.subplots(max(len(ys), 1), 1, figsize=(6, 2.2 * max(len(ys), 1)), squeeze=False)
    for ax, c in zip(axes[:, 0], ys):
        groups = {}
        for r in rec.rows:
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
