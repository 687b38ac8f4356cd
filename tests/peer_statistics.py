"""The height statistics that peers' tests assert, as they define them, to compare
rough's readers with their expectations."""

import numpy as np


def sq(heights):
    """Sq: rms about the mean over the valid points, no levelling."""
    valid = heights[~np.isnan(heights)]
    return float(np.sqrt(np.mean((valid - valid.mean()) ** 2)))


def rq(heights):
    """SurfaceTopography's rms_height_from_profile: the rms over all valid points of
    each point about its own x-profile's (row's) mean."""
    rows = np.atleast_2d(heights)
    return float(np.sqrt(np.nanmean((rows - np.nanmean(rows, axis=1, keepdims=True)) ** 2)))
