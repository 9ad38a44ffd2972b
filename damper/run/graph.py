"""Stages, their results, and the plan: which stages a scene needs and which the cache holds.

A *stage kind* (:class:`Kind`) knows how to make stage instances from a scene, what
they compute (by calling library functions directly), and how their results print.
A *stage* (:class:`Stage`) is one instance: its inputs from the scene (``params``),
the stages it reads (``deps``) and the wanted results it provides (``products``).
Its cache key hashes the kind, the inputs, the keys of its dependencies and the code
version of the modules the kind runs, so a changed input or code recomputes the stage
and everything downstream, and nothing else.

New stage kinds (the blade-damper ``upd`` stages, ``backbone``) join by adding a
:class:`Kind` to :data:`damper.run.kinds.KINDS` and their results to
:data:`damper.scene.schema.RESULTS`; the planner, cache, runner and report need no change.
"""
from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from damper.cache import Store, make_key
from damper.provenance import code_version

FILE_PREFIX = "file:"


@dataclass
class Result:
    """What a stage returns: JSON-able ``data``, named ``arrays`` and ``files`` (name -> bytes).

    ``files`` are the plots and products (FMUs) written to the output folder; ``data``
    and ``arrays`` are what dependants read. A result loaded from the cache is equal to
    the one computed.
    """

    data: dict
    arrays: dict = field(default_factory=dict)
    files: dict = field(default_factory=dict)

    def encode(self, provenance: dict) -> tuple[dict, dict]:
        """(arrays, meta) for :meth:`damper.cache.Store.put`."""
        arrays = dict(self.arrays)
        for name, blob in self.files.items():
            arrays[FILE_PREFIX + name] = np.frombuffer(blob, dtype=np.uint8)
        return arrays, {"data": self.data, "files": sorted(self.files), "provenance": provenance}

    @classmethod
    def decode(cls, arrays: dict, meta: dict) -> tuple[Result, dict]:
        """The result and its provenance from a cache entry."""
        files = {n: arrays[FILE_PREFIX + n].tobytes() for n in meta["files"]}
        plain = {k: v for k, v in arrays.items() if not k.startswith(FILE_PREFIX)}
        return cls(meta["data"], plain, files), meta["provenance"]


@dataclass
class Stage:
    """One stage of a scene's graph.

    Attributes
    ----------
    name : str
        Unique in the scene, ``kind:label`` (e.g. ``tangential:damper``).
    kind : Kind
    params : dict
        The stage's inputs from the scene (JSON-able).
    deps : tuple of str
        Names of the stages whose results it reads.
    products : tuple of str
        Wanted results it provides (``damper.scene.schema.RESULTS`` names).
    contact : str or None
        The scene's name of the contact a per-contact stage belongs to (not part of
        the key: two contacts with equal inputs share their cache entries).
    extra : dict
        What the stage needs but its key must not hold (a file's path, whose content
        hash is in ``params``).
    """

    name: str
    kind: Kind
    params: dict
    deps: tuple = ()
    products: tuple = ()
    contact: str | None = None
    extra: dict = field(default_factory=dict)
    key: str = ""
    action: str = ""
    reason: str = ""
    forced: bool = False


class Kind:
    """A stage kind; subclasses set ``name``, ``modules`` and override the methods.

    ``modules`` lists the modules or packages the kind runs: their source hash is part
    of every key (:func:`damper.provenance.code_version`).
    """

    name = ""
    modules: tuple = ()
    #: Bump when the kind's own output format changes (part of the key).
    version = 1

    def instances(self, data: dict) -> list[Stage]:
        """Every stage of this kind the validated scene ``data`` describes."""
        raise NotImplementedError

    def compute(self, stage: Stage, inputs: dict, ctx) -> Result:
        """Run the stage; ``inputs`` maps each dependency's name to its Result."""
        raise NotImplementedError

    def is_cached(self, stage: Stage, store: Store) -> bool:
        return store.contains(stage.key)

    def outputs(self, stage: Stage, result: Result) -> dict:
        """Wanted result -> file name (relative to the stage's output folder)."""
        return {}

    def lines(self, stage: Stage, result: Result) -> list[str]:
        """Summary lines printed after the stage (numbers a person reads)."""
        return []

    def scalars(self, stage: Stage, result: Result) -> dict:
        """The stage's headline numbers (name -> float, SI units) for reports and sweep tables."""
        return {}

    def warnings(self, stage: Stage, result: Result) -> list[str]:
        """The warnings the stage's result carries, each one text without a ``warning:`` prefix.

        Read from ``result.data``: its ``warning`` text, its ``warnings`` list and every
        ``*_warning`` text (``truncation_warning``, ``lift_off_warning``, ...); an empty or
        missing one is no warning. A kind whose result flags a warning otherwise (a
        boolean) adds its text by overriding this.
        """
        data = result.data if isinstance(result.data, dict) else {}
        texts = [data.get("warning")] + list(data.get("warnings") or [])
        return warning_texts(texts + [v for k, v in sorted(data.items()) if k.endswith("_warning")])

    def folder(self, stage: Stage) -> str:
        """Output sub-folder of the stage."""
        return stage.name.replace(":", "_")

    def key(self, stage: Stage, dep_keys: list[str]) -> str:
        return make_key(self.name, self.version, stage.params, dep_keys, code_version(tuple(self.modules)))


def warning_texts(texts) -> list[str]:
    """The non-empty texts of ``texts`` (None and booleans dropped), each once, without a
    leading ``warning:`` (the report and the printed lines add their own)."""
    out = []
    for t in texts:
        if isinstance(t, str) and t.strip():
            t = t.strip()
            t = t[len("warning:"):].strip() if t.lower().startswith("warning:") else t
            if t not in out:
                out.append(t)
    return out


@dataclass
class Plan:
    """The ordered stages of a scene with their action ("compute", "cached", "skip") and reason."""

    stages: list
    want: list

    def __getitem__(self, name: str) -> Stage:
        for s in self.stages:
            if s.name == name:
                return s
        raise KeyError(name)

    def to_json(self) -> list[dict]:
        return [{"name": s.name, "action": s.action, "reason": s.reason} for s in self.stages]


def build_plan(data: dict, kinds, store: Store, force=(), previous: dict | None = None) -> Plan:
    """Plan the stages the scene ``data`` needs.

    Parameters
    ----------
    data : dict
        Validated scene data (``Scene.data``).
    kinds : sequence of Kind
    store : Store
    force : sequence of str
        Stage names (or kind names: every stage of the kind) to recompute, with
        everything that depends on them.
    previous : dict, optional
        Stage name -> key of the last run in the same output folder, to say
        "inputs changed" instead of "not in the cache".
    """
    stages = [s for k in kinds for s in k.instances(data)]
    by_name = {s.name: s for s in stages}
    names = set(by_name)
    for f in force:
        if f not in names and not any(s.kind.name == f for s in stages):
            raise ValueError(f"--force {f}: no such stage in this scene (stages: {', '.join(by_name)})")
    wanted = _wanted(data, stages)
    needed = closure(wanted, by_name)
    order = _toposort([s for s in stages if s.name in needed], by_name)
    forced = set()
    for s in order:  # keys and compute/cached in dependency order
        s.key = s.kind.key(s, [by_name[d].key for d in s.deps])
        if s.name in force or s.kind.name in force or forced & set(s.deps):
            forced.add(s.name)
            s.forced = True
            s.action, s.reason = "compute", "forced" + ("" if s.name in force or s.kind.name in force
                                                         else f" (depends on {_first(forced, s.deps)})")
        elif s.kind.is_cached(s, store):
            s.action, s.reason = "cached", "in the cache"
        else:
            s.action = "compute"
            old = (previous or {}).get(s.name)
            s.reason = ("inputs or code changed since the last run here" if old and old != s.key
                        else "not in the cache")
    for s in reversed(order):  # a cached stage nobody computing needs and nobody wants: skip
        if s.action != "cached" or s.name in wanted:
            continue
        users = [o for o in order if s.name in o.deps and o.action != "skip"]
        if all(u.action == "cached" for u in users):
            s.action, s.reason = "skip", "cached, and every stage that reads it is cached"
    for s in order:
        why = wanted.get(s.name) or "needed by " + ", ".join(o.name for o in order if s.name in o.deps)
        s.reason = f"{why}; {s.reason}"
    rest = [s for s in stages if s.name not in needed]
    for s in rest:
        s.action, s.reason = "skip", "not needed for want = " + ", ".join(data["want"])
    idle = [Stage(k.name, k, {}, action="skip", reason="the scene neither wants nor describes it")
            for k in kinds if not any(s.kind is k for s in stages)]
    return Plan(order + rest + idle, list(data["want"]))


def _wanted(data: dict, stages) -> dict:
    """Stage name -> "wanted: ..." for the stages providing a wanted result."""
    out = {}
    for s in stages:
        wants = data["contact"][s.contact]["want"] if s.contact else data["want"]
        hit = [p for p in s.products if p in wants]
        if hit:
            out[s.name] = "wanted: " + ", ".join(hit)
    return out


def closure(names, stages) -> set:
    """``names`` and, transitively, every stage they depend on; ``stages`` maps a stage's
    name to the stage (its ``deps``: the names it depends on)."""
    todo, seen = list(names), set()
    while todo:
        n = todo.pop()
        if n not in seen:
            seen.add(n)
            todo.extend(stages[n].deps)
    return seen


def _toposort(stages, by_name) -> list:
    out, done = [], set()

    def visit(s):
        if s.name in done:
            return
        for d in s.deps:
            visit(by_name[d])
        done.add(s.name)
        out.append(s)

    for s in stages:
        visit(s)
    return out


def _first(names: set, deps) -> str:
    return next(d for d in deps if d in names)
