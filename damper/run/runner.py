"""Run a scene: plan, compute or load each stage, write the output folder.

Output folder (``--out``)::

    run.json                 plan (stage, action, reason), outputs, times, provenance
    report.html              one page: numbers, tables, plots, the plan (when wanted)
    <stage>/result.json      the stage's data and provenance (scene hash, code version, inputs)
    <stage>/*.png, *.fmu     its plots and products

Every file is written atomically; a scene that fails validation writes nothing, and
neither does a run that fails or is interrupted part-way (the output folder is written
once every stage has finished, so it never shows a partial run as a whole one); the
stages that finished are in the cache, so running again starts after them.
"""
from __future__ import annotations

import json
import time
from dataclasses import dataclass, field
from pathlib import Path

from contact_core.fileio import MAX_TEXT_FILE_BYTES, read_bounded
from damper.cache import Store
from damper.cli.common import atomic_write, dumps
from damper.provenance import code_version, git_revision, record

from .graph import Plan, Result, build_plan
from .kinds import KINDS
from .progress import Progress


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during a run: ``message`` says where, and that finished stages are cached."""

    def __init__(self, message: str):
        super().__init__(message)
        self.message = message


@dataclass
class Context:
    """What a stage's ``compute`` may use besides its inputs."""

    store: Store
    scene: object
    forced: set = field(default_factory=set)
    #: ``progress(done, total, label)`` for steps inside a stage (the libraries' callback), or None
    progress: object = None
    #: ``note(line)`` for a line a stage prints while it runs (as its command prints it to
    #: standard error: a cost estimate, a step's summary), or None
    note: object = None


@dataclass
class RunRecord:
    """The outcome of a run (``to_json`` is the ``--json`` object)."""

    scene: object
    plan: Plan
    results: dict = field(default_factory=dict)
    times: dict = field(default_factory=dict)
    outputs: dict = field(default_factory=dict)
    provenance: dict = field(default_factory=dict)
    out: Path | None = None

    @property
    def computed(self) -> list[str]:
        return [s.name for s in self.plan.stages if s.action == "compute"]

    def to_json(self) -> dict:
        return {"scene": self.scene.source, "scene_hash": self.scene.hash(), "want": self.plan.want,
                "stages": self.plan.to_json(), "outputs": self.outputs, "times": self.times,
                "provenance": self.provenance}


def plan_scene(scene, store: Store, force=(), out: Path | None = None, kinds=KINDS) -> Plan:
    """The plan of ``scene`` against ``store`` (``out``: the folder of a previous run, for reasons)."""
    previous = {}
    if out is not None and (Path(out) / "run.json").is_file():
        try:
            text = read_bounded(Path(out) / "run.json", MAX_TEXT_FILE_BYTES, protect=False)
            previous = json.loads(text).get("keys", {})
        except (OSError, ValueError, AttributeError):   # unreadable or not an object: no reasons
            previous = {}
    return build_plan(scene.data, kinds, store, force=force, previous=previous)


def print_plan(plan: Plan, echo) -> None:
    width = max(len(s.name) for s in plan.stages)
    echo("plan:")
    for s in plan.stages:
        echo(f"  {s.name:{width}s}  {s.action:7s}  {s.reason}")


def execute(scene, plan: Plan, store: Store, out: Path | None, progress: Progress) -> RunRecord:
    """Compute or load every stage of ``plan`` in order; write the output folder if ``out``."""
    rec = RunRecord(scene, plan, out=Path(out) if out is not None else None)
    ctx = Context(store, scene, {s.name for s in plan.stages if s.forced}, progress.step, progress.note)
    rec.provenance = record(scene=scene.source, scene_hash=scene.hash(), scene_content=scene.raw,
                            cache=None if store.memory else str(store.folder.resolve()))
    current = None
    try:
        for s in plan.stages:
            if s.action == "skip":
                continue
            current = s.name
            progress.start(s.name, s.action)
            t0 = time.perf_counter()
            result = _load(s, store) if s.action == "cached" else None
            if result is None:
                if s.action == "cached":
                    s.action, s.reason = "compute", s.reason + " (entry unreadable or gone: recomputed)"
                result = _compute(s, rec, ctx, _after(rec, out) if out is not None else "")
                store.put(s.key, *result.encode(_stage_provenance(s, scene)), stage=s.kind.name)
            rec.results[s.name] = result
            rec.times[s.name] = time.perf_counter() - t0
            progress.finish(s.name, rec.times[s.name])
            for line in s.kind.lines(s, result):
                progress.echo(line)
    except KeyboardInterrupt:
        raise Interrupted(f"interrupted in stage {current}{_after(rec, out)}") from None
    if out is not None:
        write_outputs(rec)
    return rec


def _after(rec: RunRecord, out) -> str:
    """What a failed or interrupted run leaves: the finished stages (cached), no output folder."""
    done = list(rec.results)
    where = "" if out is None else f"; nothing written to {out}/"
    if not done:
        return f" (no stage finished{where})"
    return f" (after {len(done)} finished stage(s), the last {done[-1]}: they are cached{where})"


def _compute(s, rec: RunRecord, ctx: Context, after: str = "") -> Result:
    """Run one stage; its errors keep their type (exit 2 bad input, 3 solver) and name the stage."""
    inputs = {d: rec.results[d] for d in s.deps if d in rec.results}
    try:
        return s.kind.compute(s, inputs, ctx)
    except (ValueError, RuntimeError) as err:
        base = ValueError if isinstance(err, ValueError) else RuntimeError
        raise base(f"stage {s.name}: {err}{after}") from err


def _load(s, store: Store) -> Result | None:
    hit = store.get(s.key, stage=s.kind.name)
    if hit is None:
        return None
    result, _ = Result.decode(*hit)
    if not s.kind.is_cached(s, store):   # e.g. the condensed matrices were evicted
        return None
    return result


def _stage_provenance(s, scene) -> dict:
    return {"stage": s.name, "key": s.key, "kind": s.kind.name,
            "code_version": code_version(tuple(s.kind.modules)), "modules": list(s.kind.modules),
            "inputs": s.params, "deps": list(s.deps), "scene_hash": scene.hash(),
            "git": git_revision(), "computed": time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime())}


def write_outputs(rec: RunRecord) -> None:
    """Write every finished stage's files and result.json, the outputs map, run.json, the report."""
    out = rec.out
    wanted = set(rec.plan.want)
    for s in rec.plan.stages:
        if s.name not in rec.results or s.kind.name == "condense":
            continue
        result = rec.results[s.name]
        folder = out / s.kind.folder(s)
        for name, blob in result.files.items():
            atomic_write(folder / name, blob)
        prov = _stage_provenance(s, rec.scene) | {"from_cache": s.action == "cached"}
        atomic_write(folder / "result.json", dumps({"data": result.data, "provenance": prov}, indent=1) + "\n")
        contact_wants = set(rec.scene.data["contact"][s.contact]["want"]) if s.contact else wanted
        for product, fname in s.kind.outputs(s, result).items():
            if product not in contact_wants:
                continue
            target = folder / fname
            rec.outputs.setdefault(product, []).append(str(target))
    rec.outputs = {k: v[0] if len(v) == 1 else v for k, v in rec.outputs.items()}
    if "report" in wanted:
        from damper.report.html import write_report

        rec.outputs["report"] = str(write_report(rec, out / "report.html"))
    body = rec.to_json() | {"keys": {s.name: s.key for s in rec.plan.stages if s.key}}
    atomic_write(out / "run.json", dumps(body, indent=1) + "\n")


def run_scene(scene, store: Store, out: Path | None = None, force=(), dry_run: bool = False,
              progress: Progress | None = None, echo=print) -> RunRecord:
    """Plan and run ``scene``; ``echo`` prints the plan and summary lines."""
    plan = plan_scene(scene, store, force, out)
    print_plan(plan, echo)
    if dry_run:
        return RunRecord(scene, plan)
    active = [s for s in plan.stages if s.action != "skip"]
    if progress is None:
        progress = Progress(len(active), emit=echo)
    progress.total = len(active)
    try:
        rec = execute(scene, plan, store, out, progress)
    finally:
        progress.close()
    computed = rec.computed
    if not computed:
        echo("nothing computed: every stage came from the cache")
    else:
        echo(f"computed {len(computed)} stage(s): {', '.join(computed)}; "
             f"{len(active) - len(computed)} from the cache")
    return rec
