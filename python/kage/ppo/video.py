"""Videos of a policy: one episode in a fresh environment, each frame shown with the episode's metrics
beside it, written as an animated GIF (Pillow, Debian's python3-pil) or an MP4 (the ffmpeg program, where
installed). Used by `python3 -m kage.ppo.evaluate --video` and by the trainer's --video-every (§3.6: sampled
actions, from seed + iteration; one environment instead of the original's 3 x 3 tiles, one episode)."""
import io
import os
import shutil
import subprocess
from typing import List, Optional

import numpy as np
import torch

import kage
from kage.fields import VIDEO_METRICS
from kage.ppo.counter_random import CounterRandom
from kage.ppo.policy import policy_step
from kage.ppo.wrappers import FrameStack
from kage.util.files import atomic_write

FPS = 25  # a GIF counts time in hundredths of a second: 40 ms a frame is exact
PANEL_WIDTH = 190
LARGE_VIDEO = 10 << 20  # bytes: a video past this says how to make it smaller


def check_path(path: str) -> None:
    """Refuses, before any work, a video path that cannot be written."""
    ext = os.path.splitext(path)[1].lower()
    if ext not in (".gif", ".mp4"):
        raise SystemExit(f"kage: video '{path}': write a .gif (or a .mp4 where ffmpeg is installed)")
    if ext == ".mp4" and shutil.which("ffmpeg") is None:
        raise SystemExit(f"kage: video '{path}': MP4 needs the ffmpeg program (Debian: sudo apt-get install ffmpeg); "
                         "or write a .gif")
    folder = os.path.dirname(os.path.abspath(path))
    if not os.path.isdir(folder):
        raise SystemExit(f"kage: video '{path}': the folder {folder} does not exist; create it first")


def host(array) -> np.ndarray:
    """A runtime array (numpy or DeviceArray) as a numpy copy."""
    return torch.from_dlpack(array).cpu().numpy().copy()


@torch.no_grad()
def record_frames(agent, run: int, config: str, seed: int, title: str, *, device: str, asset_root: Optional[str] = None,
                  use_frame_stack: bool = False, bf16: bool = False, greedy: bool = False, stride: int = 1):
    """Plays one episode of run `run` of the (pack) network `agent` on `config`; returns the frames of
    steps stride, 2 stride, ... and the last step (ceil(length / stride) frames), each the observation
    after that step with the metrics beside it, and the episode's length."""
    env = kage.make_vec(config, 1, device=device, asset_root=asset_root, threads=1)
    try:
        obs, info = env.reset(seed=seed)
        frame = torch.from_dlpack(obs).clone()  # [1, H, W, 3]
        stack = FrameStack(frame) if use_frame_stack else None
        num_actions = env.single_action_space.n
        random = CounterRandom([seed], device)
        counter = torch.zeros((), dtype=torch.int64, device=device)
        runs = getattr(agent, "runs", 1)
        images, step = [], 0
        while True:
            x = stack.stack if stack else frame
            uniform = random.uniform(0, counter.fill_(step), (1, num_actions))[0]
            action, _, _ = policy_step(agent, x[None].expand(runs, *x.shape), uniform[None].expand(runs, -1, -1),
                                       bf16=bf16, greedy=greedy)
            obs, _, _, _, info = env.step(action[run])
            step += 1
            done = bool(host(info["_final"])[0])
            shown, fields = (info["final_obs"], info["final_info"]) if done else (obs, info)
            if step % stride == 0 or done:
                metrics = {name: float(host(fields[name])[0]) for name in VIDEO_METRICS}
                images.append(annotate(host(shown)[0], title, step, metrics))
            if done:
                return images, step
            frame = torch.from_dlpack(obs).clone()
            if stack:
                stack.push(frame, torch.zeros(1, device=device))
    finally:
        env.close()


def annotate(frame: np.ndarray, title: str, step: int, metrics: dict):
    """The frame, enlarged to about 256 pixels, with the title, the step and the metrics on a panel beside it."""
    from PIL import Image, ImageDraw
    height, width, _ = frame.shape
    scale = max(1, 256 // max(height, width))
    image = Image.new("RGB", (width * scale + PANEL_WIDTH, max(height * scale, 130)), (24, 24, 24))
    image.paste(Image.fromarray(frame).resize((width * scale, height * scale), Image.NEAREST), (0, 0))
    lines = [title, f"step {step}"] + [f"{name} {value:.2f}" if name in ("return", "progress") else
                                       f"{name} {value:g}" for name, value in metrics.items()]
    draw = ImageDraw.Draw(image)
    for i, line in enumerate(lines):
        draw.text((width * scale + 8, 6 + 14 * i), line, fill=(235, 235, 235))
    return image


def write_video(path: str, images: List) -> None:
    """`images` (PIL, same size) as a GIF or an MP4 at FPS, replacing `path` atomically."""
    if path.lower().endswith(".gif"):
        buffer = io.BytesIO()
        images[0].save(buffer, format="GIF", save_all=True, append_images=images[1:], duration=1000 // FPS, loop=0)
        atomic_write(path, buffer.getvalue())
        return
    width, height = images[0].size
    tmp = f"{path}.tmp.{os.getpid()}.mp4"
    command = ["ffmpeg", "-y", "-loglevel", "error", "-f", "rawvideo", "-pix_fmt", "rgb24", "-s", f"{width}x{height}",
               "-r", str(FPS), "-i", "-", "-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-pix_fmt", "yuv420p", tmp]
    done = subprocess.run(command, input=b"".join(im.tobytes() for im in images), capture_output=True)
    if done.returncode != 0:
        raise SystemExit(f"kage: ffmpeg could not write {path}: {done.stderr.decode(errors='replace').strip()}")
    os.replace(tmp, path)


def size_note(path: str) -> str:
    """The written video's size, and past LARGE_VIDEO how to make the next one smaller: a GIF of frames that
    change in every pixel (pixel noise) hardly compresses, about 50 kB a frame."""
    size = os.path.getsize(path)
    note = f"{size / 1e6:.1f} MB"
    if size > LARGE_VIDEO:
        note += "; --video-stride K keeps every K-th step"
        if path.lower().endswith(".gif"):
            note += ", and an .mp4 (ffmpeg) is many times smaller"
    return note


def record(agent, run: int, config: str, seed: int, path: str, title: str, **options) -> int:
    """record_frames, then write_video to `path`; returns the episode's length."""
    images, length = record_frames(agent, run, config, seed, title, **options)
    write_video(path, images)
    return length
