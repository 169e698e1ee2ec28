"""Animates a track run: the leg in 3-D, one small multiple per mode, from its traced angles.

Usage: python3 -m leglab.results.animate RUN_DIR [--modes M ...] [--steps N] [--every K]
                                              [--fps F] --out FILE.gif|FILE.mp4

RUN_DIR is a folder `track` wrote. The leg is the run's own robot: table2.json's plant.robot
names the robot file, whose `urdf` (after its `extends:`, relative to the robot file, as the
programs resolve it) gives the joint frames from the root link to the `foot` link. Each frame
is the forward kinematics of that chain at the actual angles trace_<mode>.csv holds for a tick;
nothing is read back from foot_<mode>.csv but the stand's instruments (contact force, carriage
height). Drawn per mode: the leg, the desired foot path of one step, the foot's trail, and on
the test stand the floor, the carriage and the floor's force on the foot. Details and the
render time: docs/animation.md.

Bad input (no such folder, no traces, an unknown mode, a bad --out) prints one line naming the
item and exits 2, having written nothing; the output is written to a temporary file beside
--out and renamed when complete.
"""
from __future__ import annotations

import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from typing import Any, Iterator, Mapping, NoReturn, Sequence

import numpy as np
import numpy.typing as npt
import yaml

from .reader import read_json, read_rows
from .urdf_chain import ChainJoint, UrdfError, chain_points_cm, read_chain

__all__ = ["Animation", "InputError", "build_animation", "foot_positions", "render", "main"]

TICK_S = 0.008  # one control tick, 8 ms
# At most this many frames by default: a default run (every mode of a run, one step) then
# renders in well under 30 s on a 2-core machine (docs/animation.md has the measurement).
DEFAULT_MAX_FRAMES = 45
# The floor's force on the foot is drawn as an arrow this many cm long per newton.
FORCE_CM_PER_N = 0.5
SUFFIXES = (".gif", ".mp4")
# --fps's range: 0.01 (a frame every 100 s) to 1000 (8 times real time at one frame a tick);
# outside it a frame's duration overflows or rounds to nothing.
MIN_FPS = 0.01
MAX_FPS = 1000.0
# The programs read a robot file of at most 4 MiB (docs/configuration.md); so does this.
MAX_ROBOT_FILE_BYTES = 4 * 1024 * 1024


def _repo_root() -> str:
    """Where a relative robot file is looked for besides the working folder: the source tree
    (this package linked into a build, or python/ itself), else leglab's installed data."""
    source = os.path.realpath(__file__)
    for _ in range(4):
        source = os.path.dirname(source)
    if os.path.isdir(os.path.join(source, "robots")) or "LEGLAB_DATA_DIR" not in os.environ:
        return source
    return os.environ["LEGLAB_DATA_DIR"]


REPO_ROOT = _repo_root()


class InputError(Exception):
    """Bad input from the user: one line naming the item; the program exits 2."""


def one_line(text: object) -> str:
    """`text` with control and undecodable characters escaped: a message stays one line."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in str(text))


class ArgumentParser(argparse.ArgumentParser):
    """argparse, with a bad flag reported as every other bad input: one line, status 2 (not
    argparse's usage block)."""

    def error(self, message: str) -> NoReturn:
        print(f"animate.py: {one_line(message)} (see --help)", file=sys.stderr)
        sys.exit(2)


_Array = npt.NDArray[np.float64]
# Per (step, tick) of a trace: ({joint: actual rad}, {joint: desired rad}).
_Angles = dict[tuple[int, int], tuple[dict[str | None, float], dict[str | None, float]]]


# --- The run --------------------------------------------------------------------------------


def top_level_keys(path: str) -> dict[str, str]:
    """A robot file's top-level scalars (its `urdf` and `extends` are what is needed here), as
    text, read with a YAML parser (python3-yaml's safe loader)."""
    try:
        if os.path.getsize(path) > MAX_ROBOT_FILE_BYTES:
            raise InputError(f"robot file '{path}': over {MAX_ROBOT_FILE_BYTES} bytes")
        with open(path, encoding="utf-8") as f:
            data = yaml.safe_load(f)
    except (OSError, UnicodeDecodeError, yaml.YAMLError, RecursionError) as e:
        one_line = " ".join(str(e).split()) or type(e).__name__
        raise InputError(f"robot file '{path}': {one_line}") from None
    if data is None:
        return {}
    if not isinstance(data, dict):
        raise InputError(f"robot file '{path}': not a mapping of keys")
    return {str(k): str(v) for k, v in data.items()
            if isinstance(v, (str, int, float)) and not isinstance(v, bool)}


def robot_urdf(robot_yaml: str) -> str:
    """The URDF a robot file names, after its `extends:` (a file's own `urdf` wins over its
    base's), relative to the robot file itself, as the programs resolve it."""
    path = robot_yaml
    for _ in range(8):
        keys = top_level_keys(path)
        if "urdf" in keys:
            return os.path.join(os.path.dirname(robot_yaml), keys["urdf"])
        if "extends" not in keys:
            break
        path = os.path.join(os.path.dirname(path), keys["extends"])
    raise InputError(f"robot file '{robot_yaml}': no urdf")


@dataclass
class Run:
    """What a track run folder says about itself."""

    folder: str
    robot_yaml: str
    urdf: str
    chain: list[ChainJoint]
    stand: dict[str, Any] | None  # table2.json's plant.stand, or None in the air
    modes: list[str]  # in run order


def load_run(folder: str) -> Run:
    """The run in `folder`: its robot, the URDF chain and the modes traced; InputError naming
    the item when it is not a track run."""
    if not os.path.isdir(folder):
        raise InputError(f"run folder '{folder}': no such folder")
    traced = sorted(name[len("trace_"):-len(".csv")] for name in os.listdir(folder)
                    if name.startswith("trace_") and name.endswith(".csv"))
    if not traced:
        raise InputError(f"run folder '{folder}': no trace_<mode>.csv")
    table = os.path.join(folder, "table2.json")
    try:
        data = read_json(table)
    except (OSError, ValueError, RecursionError) as e:
        raise InputError(f"'{table}': {e}") from None
    plant = data.get("plant", {}) if isinstance(data, dict) else None
    if not isinstance(plant, dict):
        raise InputError(f"'{table}': expected a JSON object with a 'plant' object, as track "
                         "writes it")
    robot_yaml = plant.get("robot")
    if robot_yaml is not None and not isinstance(robot_yaml, str):
        raise InputError(f"'{table}': plant.robot is not a file name")
    if not robot_yaml:
        raise InputError(f"'{table}': no plant.robot (a run of an older track?)")
    # A relative robot file is relative to where track ran: most often the repository root.
    if not os.path.isabs(robot_yaml) and not os.path.exists(robot_yaml):
        from_root = os.path.join(REPO_ROOT, robot_yaml)
        if not os.path.exists(from_root):
            raise InputError(f"'{table}': robot file '{robot_yaml}' not found here or in "
                             f"'{REPO_ROOT}' (run from where track ran)")
        robot_yaml = from_root
    urdf = robot_urdf(robot_yaml)
    try:
        chain = read_chain(urdf)
    except UrdfError as e:
        raise InputError(str(e)) from None
    # Run order: per_step.csv takes each mode's rows as its run finishes.
    order: list[str] = []
    per_step = os.path.join(folder, "per_step.csv")
    if os.path.exists(per_step):
        for row in read_rows(per_step):
            if row.mode in traced and row.mode not in order:
                order.append(row.mode)
    modes = order + [m for m in traced if m not in order]
    stand = plant.get("stand")
    if stand is not None and not isinstance(stand, dict):
        raise InputError(f"'{table}': plant.stand is not an object")
    return Run(folder, robot_yaml, urdf, chain, stand, modes)


@dataclass
class Animation:
    """Everything drawn, per frame and mode.

    Positions in cm in the root link's frame (the body frame of foot_<mode>.csv):
    `legs[mode][f]` is the chain's points at frame f, root to foot; on the stand the drawing
    lifts them by the carriage's height.

    Attributes
    ----------
    run : Run
        The track run drawn.
    modes : list of str
        The modes drawn, one panel each.
    frames : list of (int, int)
        (step, tick) per frame.
    period : int
        Ticks per step.
    legs : dict of str to numpy.ndarray
        Mode -> (frames, points, 3): the chain's points per frame.
    desired_cm : numpy.ndarray
        (period, 3): one step's desired foot path (none, (0, 3), until build_animation sets
        it).
    carriage_cm : dict of str to numpy.ndarray
        Mode -> (frames,): the carriage's height, 0 in the air.
    force_n : dict of str to numpy.ndarray
        Mode -> (frames, 3): the floor's force on the foot, x, y, z.
    """

    run: Run
    modes: list[str]
    frames: list[tuple[int, int]]  # (step, tick) per frame
    period: int  # ticks per step
    legs: dict[str, _Array] = field(default_factory=dict)  # mode -> (frames, points, 3)
    # (period, 3): one step's desired foot path
    desired_cm: _Array = field(default_factory=lambda: np.zeros((0, 3)))
    carriage_cm: dict[str, _Array] = field(default_factory=dict)  # mode -> (frames,), 0 in the air
    force_n: dict[str, _Array] = field(default_factory=dict)  # mode -> (frames, 3): x, y, z


def read_trace(run: Run, mode: str) -> tuple[_Angles, int]:
    """(step, tick) -> ({joint: actual rad}, {joint: desired rad}), and the step's ticks."""
    path = os.path.join(run.folder, f"trace_{mode}.csv")
    angles: _Angles = {}
    period = 0
    try:
        for row in read_rows(path):
            key = (int(row.step), int(row.tick))
            actual, desired = angles.setdefault(key, ({}, {}))
            for target, text, what in ((actual, row.actual_deg, "the actual angle"),
                                       (desired, row.desired_deg, "the desired angle")):
                value = float(text)
                if not math.isfinite(value):
                    raise ValueError(f"step {key[0]} tick {key[1]} {row.joint}: {what} is "
                                     f"{value}")
                target[row.joint] = math.radians(value)
            period = max(period, key[1] + 1)
    except (OSError, AttributeError, ValueError) as e:
        raise InputError(f"'{path}': unreadable ({e})") from None
    if not angles:
        raise InputError(f"'{path}': no ticks")
    names = [j.name for j in run.chain if j.kind != "fixed"]
    for key, (actual, _) in angles.items():
        missing = [n for n in names if n not in actual]
        if missing:
            raise InputError(f"'{path}': step {key[0]} tick {key[1]} lacks joint {missing[0]}")
    return angles, period


def build_animation(folder: str, modes: Sequence[str] | None = None, steps: int = 1,
                    every: int | None = None) -> Animation:
    """Everything an animation of a track run draws.

    Parameters
    ----------
    folder : str
        A folder track wrote.
    modes : sequence of str, optional
        The modes to draw (default every mode present, in run order).
    steps : int
        The measured steps to draw, from the first.
    every : int, optional
        Draw every `every`-th tick (default: at most DEFAULT_MAX_FRAMES frames).

    Returns
    -------
    Animation
        The frames, and per mode the leg's points, the carriage and the floor's force.

    Raises
    ------
    InputError
        One line naming a bad item (the folder, a file, a mode, a flag's value).
    """
    run = load_run(folder)
    modes = list(modes or run.modes)
    for mode in modes:
        if mode not in run.modes:
            raise InputError(f"mode '{mode}': not in the run (it has {', '.join(run.modes)})")
    if steps < 1:
        raise InputError(f"--steps {steps}: expected at least 1")
    if every is not None and every < 1:
        raise InputError(f"--every {every}: expected at least 1")
    traces = {mode: read_trace(run, mode) for mode in modes}
    period = traces[modes[0]][1]
    available = 1 + max(step for step, _ in traces[modes[0]][0])
    if steps > available:
        raise InputError(f"--steps {steps}: the run measured {available}")
    ticks = steps * period
    every = every or max(1, math.ceil(ticks / DEFAULT_MAX_FRAMES))
    frames = [(i // period, i % period) for i in range(0, ticks, every)]
    anim = Animation(run, modes, frames, period)
    first_angles = traces[modes[0]][0]
    anim.desired_cm = np.array(
        [chain_points_cm(run.chain, first_angles[(0, t)][1])[-1] for t in range(period)])
    for mode in modes:
        angles = traces[mode][0]
        for frame in frames:
            if frame not in angles:
                raise InputError(f"'trace_{mode}.csv': no step {frame[0]} tick {frame[1]}")
        anim.legs[mode] = np.array([chain_points_cm(run.chain, angles[f][0]) for f in frames])
        carriage = np.zeros(len(frames))
        force = np.zeros((len(frames), 3))
        if run.stand is not None:
            path = os.path.join(run.folder, f"foot_{mode}.csv")
            try:
                rows = {(int(r.step), int(r.tick)): r for r in read_rows(path)}
                for i, f in enumerate(frames):
                    carriage[i] = float(rows[f].carriage_z_mm) / 10.0
                    force[i] = [float(rows[f].contact_fx_n), float(rows[f].contact_fy_n),
                                float(rows[f].contact_fz_n)]
            except (OSError, KeyError, AttributeError, ValueError) as e:
                raise InputError(f"'{path}': no stand column or tick ({e})") from None
        anim.carriage_cm[mode] = carriage
        anim.force_n[mode] = force
    return anim


def foot_positions(folder: str, modes: Sequence[str] | None = None, steps: int = 1,
                   every: int | None = None) -> dict[str, list[tuple]]:
    """The foot per mode and frame as the animation draws it.

    Parameters
    ----------
    folder, modes, steps, every
        As build_animation's.

    Returns
    -------
    dict
        {mode: [(step, tick, (x, y, z)), ...]}, in foot_<mode>.csv's units and frame (cm, body
        frame).

    Raises
    ------
    InputError
        As build_animation.
    """
    anim = build_animation(folder, modes, steps, every)
    return {mode: [(s, t, tuple(anim.legs[mode][i][-1])) for i, (s, t) in enumerate(anim.frames)]
            for mode in anim.modes}


# --- Drawing ----------------------------------------------------------------------------------


def floor_z_cm(stand: Mapping[str, Any]) -> float:
    """The floor's height in the body frame at walking height (carriage 0): the walk's ground
    plus the ball of the foot's radius below the shoulder (sim/src/ode_stand.cc), the shoulder
    being at the body frame's z = 0 on the ERS-210A."""
    return -(stand["ground_below_shoulder_mm"] + stand["foot_radius_mm"]) / 10.0


def limits(anim: Animation) -> list[tuple[float, float]]:
    """One box for every subplot: the legs, the path, the floor and the arrows, with a margin."""
    points = [anim.desired_cm]
    for mode in anim.modes:
        lifted = anim.legs[mode] + np.array([0, 0, 1.0]) * anim.carriage_cm[mode][:, None, None]
        points.append(lifted.reshape(-1, 3))
        points.append(lifted[:, -1, :] + anim.force_n[mode] * FORCE_CM_PER_N)
    if anim.run.stand is not None:
        z = floor_z_cm(anim.run.stand)
        points.append(np.array([[points[0][0, 0], points[0][0, 1], z]]))
    everything = np.concatenate(points)
    low, high = everything.min(axis=0) - 1.0, everything.max(axis=0) + 1.0
    return list(zip(low, high))


def draw_panel(fig: Any, shape: tuple[int, int], k: int, anim: Animation,
               box: Sequence[tuple[float, float]]) -> dict[str, Any]:
    """Mode k's 3-D axes at place k of `shape` (rows, columns): its limits, view and labels,
    the desired path and, on the stand, the floor and the rail, drawn once; and its moving
    artists (trail, leg, carriage on the stand), empty, as a dict with the axes."""
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mode, stand = anim.modes[k], anim.run.stand
    ax = fig.add_subplot(*shape, k + 1, projection="3d")
    ax.set_xlim(*box[0])
    ax.set_ylim(*box[1])
    ax.set_zlim(*box[2])
    ax.set_box_aspect([high - low for low, high in box])  # one scale on every axis
    ax.view_init(elev=15, azim=-65)
    ax.set_title(mode, fontsize=9, pad=0)
    ax.tick_params(labelsize=6, pad=0)
    ax.set_xlabel("x (cm)", fontsize=7, labelpad=-6)
    ax.set_ylabel("y (cm)", fontsize=7, labelpad=-6)
    ax.set_zlabel("z (cm)", fontsize=7, labelpad=-6)
    path = np.vstack([anim.desired_cm, anim.desired_cm[:1]])
    ax.plot(path[:, 0], path[:, 1], path[:, 2], "k--", lw=0.8)
    carriage = None
    if stand is not None:
        z = floor_z_cm(stand)
        (x0, x1), (y0, y1) = box[0], box[1]
        ax.add_collection3d(Poly3DCollection(
            [[(x0, y0, z), (x1, y0, z), (x1, y1, z), (x0, y1, z)]], color="tan", alpha=0.3))
        # The rail through the root link's origin; the carriage a plate on it.
        ax.plot([0, 0], [0, 0], list(box[2]), color="grey", lw=0.8)
        carriage = Poly3DCollection([[(0, 0, 0)] * 4], color="grey", alpha=0.6,
                                    animated=True)
        ax.add_collection3d(carriage)
    trail, = ax.plot([], [], [], color=f"C{k % 10}", lw=1.8, animated=True)
    leg, = ax.plot([], [], [], "-o", color="k", lw=2, ms=3, animated=True)
    return {"ax": ax, "trail": trail, "leg": leg, "carriage": carriage}


def draw_moving(anim: Animation, i: int, mode: str, a: Mapping[str, Any]) -> None:
    """Frame i's moving artists of `mode`'s panel `a` (draw_panel's): the trail, the leg, the
    carriage and the floor's force arrow on the stand, each drawn on its axes."""
    stand, ax = anim.run.stand, a["ax"]
    lift = anim.carriage_cm[mode]
    points = anim.legs[mode][i] + np.array([0.0, 0.0, lift[i]])
    feet = anim.legs[mode][: i + 1, -1, :] + np.outer(lift[: i + 1], [0, 0, 1])
    a["trail"].set_data_3d(feet[:, 0], feet[:, 1], feet[:, 2])
    a["leg"].set_data_3d(points[:, 0], points[:, 1], points[:, 2])
    moving = [a["trail"], a["leg"]]
    if a["carriage"] is not None:
        z, half = lift[i], 1.5
        a["carriage"].set_verts(
            [[(-half, -half, z), (half, -half, z), (half, half, z), (-half, half, z)]])
        moving.insert(0, a["carriage"])
    force = anim.force_n[mode][i]
    arrow = None
    if stand is not None and np.linalg.norm(force) > 0:
        # From where the ball of the foot meets the floor.
        contact = points[-1] - np.array([0.0, 0.0, stand["foot_radius_mm"] / 10.0])
        tip = force * FORCE_CM_PER_N
        arrow = ax.quiver(*contact, *tip, color="red", lw=1.5,
                          arrow_length_ratio=0.25, animated=True)
        moving.append(arrow)
    for artist in moving:
        # A collection is projected by its axes' draw, which the frames skip.
        if hasattr(artist, "do_3d_projection") and not hasattr(artist, "set_data_3d"):
            artist.do_3d_projection()
        ax.draw_artist(artist)
    if arrow is not None:
        arrow.remove()


def render_frames(anim: Animation) -> Iterator[npt.NDArray[np.uint8]]:
    """Yields each frame as an RGB array (rows, columns, 3). The axes, the floor and the desired
    path are drawn once; each frame restores that picture and draws only what moves (the
    legs, trails, carriages, arrows and the counter): the 3-D axes are most of the drawing."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    columns = min(3, len(anim.modes))
    rows = math.ceil(len(anim.modes) / columns)
    fig = plt.figure(figsize=(3.2 * columns, 3.0 * rows + 0.3), dpi=80)
    box = limits(anim)
    counter = fig.text(0.01, 0.99, "", va="top", fontsize=9, family="monospace", animated=True)
    robot = os.path.basename(os.path.dirname(os.path.abspath(anim.run.robot_yaml)))
    fig.text(0.99, 0.99, f"{robot}; dashed: desired foot path" +
             (f"; arrow: floor force, 1 cm = {1 / FORCE_CM_PER_N:g} N" if anim.run.stand else ""),
             va="top", ha="right", fontsize=7)
    artists = [draw_panel(fig, (rows, columns), k, anim, box) for k in range(len(anim.modes))]
    fig.subplots_adjust(left=0, right=1, bottom=0, top=0.93, wspace=0, hspace=0.08)
    fig.canvas.draw()  # everything but the animated artists
    background = fig.canvas.copy_from_bbox(fig.bbox)
    try:
        for i, (step, tick) in enumerate(anim.frames):
            fig.canvas.restore_region(background)
            counter.set_text(f"step {step} tick {tick:3d}/{anim.period}  "
                             f"t = {(step * anim.period + tick) * TICK_S:5.3f} s")
            fig.draw_artist(counter)
            for mode, a in zip(anim.modes, artists):
                draw_moving(anim, i, mode, a)
            yield np.asarray(fig.canvas.buffer_rgba())[:, :, :3].copy()
    finally:
        plt.close(fig)


def render(anim: Animation, out_path: str, fps: float) -> None:
    """Writes an animation: a GIF through Pillow, an MP4 through ffmpeg.

    Parameters
    ----------
    anim : Animation
        build_animation()'s result.
    out_path : str
        The file, ending in .gif or .mp4.
    fps : float
        Frames per second.

    Raises
    ------
    RuntimeError
        When ffmpeg fails.
    """
    if out_path.endswith(".gif"):
        from PIL import Image

        # One palette per frame by octree, undithered: the default leaves the thin trails grey.
        images = [Image.fromarray(frame).quantize(256, Image.Quantize.FASTOCTREE,
                                                  dither=Image.Dither.NONE)
                  for frame in render_frames(anim)]
        images[0].save(out_path, save_all=True, append_images=images[1:],
                       duration=round(1000 / fps), loop=0)
        return
    frames = render_frames(anim)
    first = next(frames)
    rows, columns = first.shape[:2]
    command = ["ffmpeg", "-loglevel", "error", "-y", "-f", "rawvideo", "-pix_fmt", "rgb24",
               "-s", f"{columns}x{rows}", "-r", f"{fps:g}", "-i", "-",
               "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p",
               "-f", "mp4", out_path]
    with subprocess.Popen(command, stdin=subprocess.PIPE, stderr=subprocess.PIPE) as ffmpeg:
        stdin, stderr = ffmpeg.stdin, ffmpeg.stderr
        if stdin is None or stderr is None:  # never: both are pipes
            raise RuntimeError("ffmpeg failed: no pipe to it")
        try:
            stdin.write(first.tobytes())
            for frame in frames:
                stdin.write(frame.tobytes())
        except BrokenPipeError:
            pass
        stdin.close()
        error = stderr.read().decode(errors="replace").strip()
        if ffmpeg.wait() != 0:
            raise RuntimeError(f"ffmpeg failed: {error.splitlines()[-1] if error else '?'}")


def main(argv: Sequence[str] | None = None) -> int:
    """The command: ``python3 -m leglab.results.animate RUN_DIR [--modes M ...] [--steps N]
    [--every K] [--fps F] --out FILE.gif|FILE.mp4``.

    Parameters
    ----------
    argv : sequence of str, optional
        The arguments (default sys.argv[1:]).

    Returns
    -------
    int
        The exit status: 0, or 2 on bad input (one line on stderr, nothing written).

    Raises
    ------
    SystemExit
        Status 2 on a usage error.
    """
    parser = ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("run_dir", help="a folder track wrote")
    parser.add_argument("--modes", nargs="+", help="modes to draw (default: every mode run)")
    parser.add_argument("--steps", type=int, default=1,
                        help="measured steps to draw from the first (default 1)")
    parser.add_argument("--every", type=int, default=None,
                        help=f"draw every K-th tick (default: at most {DEFAULT_MAX_FRAMES} "
                             "frames)")
    parser.add_argument("--fps", type=float, default=10.0,
                        help=f"frames per second, {MIN_FPS:g} to {MAX_FPS:g} (default 10)")
    parser.add_argument("--out", required=True, help="the animation, FILE.gif or FILE.mp4")
    args = parser.parse_args(argv)
    try:
        suffix = os.path.splitext(args.out)[1].lower()
        if suffix not in SUFFIXES:
            raise InputError(f"--out '{args.out}': expected a .gif or .mp4 file")
        out_dir = os.path.dirname(os.path.abspath(args.out))
        if not os.path.isdir(out_dir):
            raise InputError(f"--out '{args.out}': no folder '{out_dir}'")
        if os.path.isdir(args.out):
            raise InputError(f"--out '{args.out}': is a folder, not a file")
        if not os.access(out_dir, os.W_OK | os.X_OK):
            raise InputError(f"--out '{args.out}': the folder '{out_dir}' cannot be written")
        if not MIN_FPS <= args.fps <= MAX_FPS:
            raise InputError(f"--fps {args.fps}: expected a number from {MIN_FPS:g} to "
                             f"{MAX_FPS:g}")
        if suffix == ".mp4" and shutil.which("ffmpeg") is None:
            raise InputError(f"--out '{args.out}': an .mp4 needs ffmpeg on PATH")
        anim = build_animation(args.run_dir, args.modes, args.steps, args.every)
    except InputError as e:
        print(f"animate.py: {one_line(e)}", file=sys.stderr)
        return 2
    try:
        handle, partial = tempfile.mkstemp(suffix=suffix, prefix=".animate-", dir=out_dir)
    except OSError as e:
        print(f"animate.py: --out '{one_line(args.out)}': cannot be written ({one_line(e)})",
              file=sys.stderr)
        return 2
    os.close(handle)
    try:
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(partial, 0o666 & ~umask)  # mkstemp's file is private; the output need not be
        render(anim, partial, args.fps)
        os.replace(partial, args.out)
    finally:
        if os.path.exists(partial):
            os.remove(partial)
    print(f"animation: {args.out} ({len(anim.frames)} frames, {len(anim.modes)} modes)")
    return 0


if __name__ == "__main__":
    sys.exit(main())
