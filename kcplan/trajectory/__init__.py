"""Trajectories along joint-space paths: curves with blended corners
(:mod:`kcplan.trajectory.curve`) and their time-optimal timing within joint limits
(:mod:`kcplan.trajectory.timing`, TOPP-RA). Mathematics only: no OMPL, no FCL; the
certificate of a curve lives in :mod:`kcplan.planning.smoothing`."""

from kcplan.trajectory.curve import BlendedPath
from kcplan.trajectory.timing import Trajectory, time_path

__all__ = ["BlendedPath", "Trajectory", "time_path"]
