"""The episode metrics in info follow spec 5.8: progress and success from passed_distance."""
import numpy as np

import kage
from support import NEAR_GOAL, policy

DIST_TO_SUCCESS = np.float32(12.0)  # tests/python/configs/near_goal.yaml


def test_progress_and_success_follow_passed_distance():
    seen_success = seen_failure = 0
    with kage.make_vec(NEAR_GOAL, 6) as env:
        env.reset(seed=4)
        once = np.zeros(6, dtype=bool)
        for a in policy(5, 6, 120):
            _, _, _, _, info = env.step(a)
            for table, rows in ((info, ~info["_final"].astype(bool)), (info["final_info"], info["_final"].astype(bool))):
                d = table["passed_distance"][rows]
                assert np.array_equal(table["progress"][rows], d / DIST_TO_SUCCESS)
                assert np.array_equal(table["success"][rows].astype(bool), d >= DIST_TO_SUCCESS)
            live = ~info["_final"].astype(bool)
            once = np.where(info["_final"].astype(bool), False, once | info["success"].astype(bool))
            assert np.array_equal(info["success_once"][live].astype(bool), once[live])
            seen_success += int(info["success"].sum())
            seen_failure += int((info["success"] == 0).sum())
    assert seen_success > 0 and seen_failure > 0, "both outcomes occur"


def test_return_and_length_accumulate():
    with kage.make_vec(NEAR_GOAL, 2) as env:
        env.reset(seed=0)
        total = np.zeros(2, dtype=np.float32)
        for t, a in enumerate(policy(6, 2, 40), start=1):
            _, reward, _, _, info = env.step(a)
            total += reward
        assert info["_final"].all()
        np.testing.assert_allclose(info["final_info"]["return"], total, rtol=1e-5)
        assert info["final_info"]["length"].tolist() == [40, 40]
