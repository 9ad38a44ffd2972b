"""Helpers of the application tests."""
from pathlib import Path

SMALL = Path(__file__).resolve().parent / "small_scene.toml"


def plan_actions(plan) -> dict:
    """Stage name -> action."""
    return {s.name: s.action for s in plan.stages}
