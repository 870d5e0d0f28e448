"""Typed, frozen views of a plan's steps (``docs/plan-format.md``): :class:`Step`,
:class:`Motion`, :class:`Move`, :class:`Subassembly` and :class:`RobotStep`.

:attr:`asp.Plan.steps` reads them from the plan JSON; the dict views
(:attr:`asp.Plan.assembly_sequence`) stay for code that wants the JSON as it is. Keys a newer
format adds are ignored here, as the format asks of readers.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Literal, cast

__all__ = ["Motion", "Move", "RobotStep", "Step", "Subassembly", "steps_of"]

Vec3 = tuple[float, float, float]
#: A pose: translation then unit quaternion ``(x, y, z, qx, qy, qz, qw)``.
Pose = tuple[float, float, float, float, float, float, float]
MotionKind = Literal["linear", "path", "screw"]


def _vec3(v: Any) -> Vec3:
    x, y, z = (float(c) for c in v)
    return (x, y, z)


def _pose(v: Any) -> Pose:
    x, y, z, qx, qy, qz, qw = (float(c) for c in v)
    return (x, y, z, qx, qy, qz, qw)


@dataclass(frozen=True)
class Motion:
    """How a part goes in (``docs/plan-format.md``, Motions). ``linear`` and ``screw`` have a
    unit ``direction`` and a ``distance`` (the part starts that far back along ``-direction``);
    ``screw`` also the ``axis_point`` of its axis; ``path`` has ``poses`` (waypoints from
    outside to the assembled pose, the last the identity) turning about ``pivot``."""

    kind: MotionKind
    direction: Vec3 | None = None
    distance: float | None = None
    axis_point: Vec3 | None = None
    poses: tuple[Pose, ...] = ()
    pivot: Vec3 | None = None

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Motion:
        """The motion of a plan JSON ``motion`` object."""
        kind = d["kind"]
        if kind not in ("linear", "path", "screw"):
            raise ValueError(f"unknown motion kind {kind!r}")
        return cls(
            kind=cast(MotionKind, kind),
            direction=_vec3(d["direction"]) if "direction" in d else None,
            distance=float(d["distance"]) if "distance" in d else None,
            axis_point=_vec3(d["axis_point"]) if "axis_point" in d else None,
            poses=tuple(_pose(p) for p in d.get("poses", [])),
            pivot=_vec3(d["pivot"]) if "pivot" in d else None,
        )


@dataclass(frozen=True)
class Move:
    """A rigid translation of parts already in place, made after a step (grid plans)."""

    parts: tuple[int, ...]
    translation: Vec3


@dataclass(frozen=True)
class RobotStep:
    """What the robot planned for a step (``--robot``; ``docs/plan-format.md``, Robot)."""

    grasp: Pose
    grasp_width: float
    #: Joint waypoints in disassembly direction (radians; metres for prismatic joints).
    joint_trajectory: tuple[tuple[float, ...], ...]
    gripper_path: tuple[Vec3, ...]
    path_length: float


@dataclass(frozen=True)
class Subassembly:
    """Several parts that go in at one step as one rigid body, and how they are built on their
    base: ``status`` ``found``, ``partial``, ``no_plan``, ``budget_exhausted`` or
    ``unplanned``; ``steps`` puts the other parts onto the base."""

    parts: tuple[int, ...]
    status: str
    steps: tuple[Step, ...]


@dataclass(frozen=True)
class Step:
    """One step in assembly order: ``part`` (for a subassembly, its base) goes in along
    ``motion``; then the ``moves``, if any. ``held``: parts a second gripper holds meanwhile."""

    part: int
    name: str
    motion: Motion
    subassembly: Subassembly | None = None
    moves: tuple[Move, ...] = ()
    robot: RobotStep | None = None
    held: tuple[int, ...] = ()

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Step:
        """The step of one plan JSON ``assembly_sequence`` entry."""
        sub = d.get("subassembly")
        robot = d.get("robot")
        return cls(
            part=int(d["part"]),
            name=str(d["name"]),
            motion=Motion.from_dict(d["motion"]),
            subassembly=None
            if sub is None
            else Subassembly(
                parts=tuple(int(p) for p in sub["parts"]),
                status=str(sub["status"]),
                steps=steps_of(sub.get("assembly_sequence", [])),
            ),
            moves=tuple(Move(tuple(int(p) for p in m["parts"]), _vec3(m["translation"])) for m in d.get("moves", [])),
            robot=None
            if robot is None
            else RobotStep(
                grasp=_pose(robot["grasp"]),
                grasp_width=float(robot["grasp_width"]),
                joint_trajectory=tuple(tuple(float(q) for q in row) for row in robot["joint_trajectory"]),
                gripper_path=tuple(_vec3(p) for p in robot["gripper_path"]),
                path_length=float(robot["path_length"]),
            ),
            held=tuple(int(p) for p in d.get("held", [])),
        )


def steps_of(entries: list[dict[str, Any]]) -> tuple[Step, ...]:
    """The steps of a plan JSON sequence (``assembly_sequence`` or
    ``partial_assembly_sequence``)."""
    return tuple(Step.from_dict(e) for e in entries)
