"""Videos through Gymnasium's own wrapper: `gymnasium.wrappers.vector.RecordVideo` over the Gymnasium
vector adapter writes an episode of world 0 (moviepy, in the main venv)."""

from __future__ import annotations

import numpy as np
import pytest

gym = pytest.importorskip("gymnasium")
pytest.importorskip("moviepy")
imageio_ffmpeg = pytest.importorskip("imageio_ffmpeg")

from gymnasium.wrappers.vector import RecordVideo  # noqa: E402

from colcos.gymnasium_vector import ColcosVectorEnv  # noqa: E402


def test_record_video_writes_an_episode_of_world_zero(tmp_path):
    env = ColcosVectorEnv("aggregation", num_envs=2, max_cycles=25, autoreset_mode="next_step")
    assert env.metadata["render_fps"] == 50
    frames = env.render()
    assert len(frames) == env.num_envs
    assert frames[0] is frames[1]  # the agents of a world share its frame
    assert frames[0].dtype == np.uint8 and frames[0].ndim == 3
    env = RecordVideo(env, str(tmp_path), record_first_only=True, episode_trigger=lambda e: e == 0)
    env.reset(seed=0)
    for _ in range(25):
        env.step(env.action_space.sample())
    env.close()
    videos = sorted(tmp_path.glob("*.mp4"))
    assert videos, list(tmp_path.iterdir())
    n, seconds = imageio_ffmpeg.count_frames_and_secs(str(videos[0]))
    assert n >= 25 and seconds == pytest.approx(n / 50, abs=0.1)


def test_frames_refuse_bad_indices():
    env = ColcosVectorEnv("aggregation", num_envs=1)
    frames = env.render()
    with pytest.raises(IndexError):
        frames[len(frames)]
    assert frames[-1].shape == frames[0].shape
    env.close()
