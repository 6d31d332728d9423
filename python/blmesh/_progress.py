"""Progress of a run: a caller's callable, or a bar (tqdm's when installed, else lines on stderr)."""

import contextlib
import sys


@contextlib.contextmanager
def observer(progress):
    """The callable ``(stage, fraction)`` to hand to the native run for `progress`, or None."""
    if progress is None or progress is False:
        yield None
    elif callable(progress):
        yield progress
    elif progress is True:
        bar = _Bar()
        try:
            yield bar
        finally:
            bar.close()
    else:
        raise TypeError("progress must be a callable (stage, fraction), True, False or None")


class _Bar:
    """One bar: the stage as its label, the fraction of the stage done as its length."""

    def __init__(self):
        try:
            from tqdm.auto import tqdm
        except ImportError:
            tqdm = None
        self.tqdm = tqdm and tqdm(total=100, bar_format="{desc:>10} |{bar}| {elapsed}")
        self.stage = None

    def __call__(self, stage, fraction):
        if self.tqdm is not None:
            self.tqdm.set_description_str(stage, refresh=False)
            self.tqdm.n = round(100 * fraction)
            self.tqdm.refresh()
        elif stage != self.stage:
            print(f"blmesh: {stage}", file=sys.stderr, flush=True)
        self.stage = stage

    def close(self):
        if self.tqdm is not None:
            self.tqdm.close()
