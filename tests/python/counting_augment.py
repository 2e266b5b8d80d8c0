"""An augmentation for the tests (--augment counting_augment:count): returns the frames unchanged and
counts its calls and the frames it saw, so a test can tell where the trainer applies it."""
calls = []  # the number of frames of each call


def count(obs, uniform):
    assert uniform((3,)).shape == (obs.shape[0], 3)
    calls.append(obs.shape[0] * obs.shape[1])
    return obs
