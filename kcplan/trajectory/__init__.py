"""What is done to a path once found: curves, blends proved free, timing.

The mathematics: joint-space curves with blended corners (:mod:`.curve`), their
time-optimal timing within joint limits (:mod:`.timing`, TOPP-RA) and a rigid robot's
edge-by-edge timing (:mod:`.rigid`), numpy and toppra only. The certified
post-processing on top: an arm's corners replaced by blends proved free
(:mod:`.smoothing`, with the arm certifier's bounds) and the certified, timed trajectory
of a planned path (:mod:`.certified`). No OMPL, no FCL."""

from kcplan.trajectory.curve import BlendedPath
from kcplan.trajectory.timing import Trajectory, time_path

__all__ = ["BlendedPath", "Trajectory", "time_path"]
