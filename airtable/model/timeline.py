"""Where the view is in the rewind history: what the teacher's timeline bar and every student's show."""

from __future__ import annotations

from dataclasses import dataclass


@dataclass(frozen=True)
class Timeline:
    """Where the view is in the history, for the timeline bar: simulated times in seconds."""

    oldest_s: float
    newest_s: float
    view_s: float
    frames: int  # moments kept
    index: int  # the moment on view, 0 = oldest

    @property
    def fraction(self) -> float:
        """Where the view is along the bar, 0 (oldest) to 1 (newest)."""
        span = self.newest_s - self.oldest_s
        if span > 0.0:
            return min(1.0, max(0.0, (self.view_s - self.oldest_s) / span))
        return self.index / (self.frames - 1) if self.frames > 1 else 1.0
