"""Input and output: gyro-log readers with validation, BROAD recordings, atomic file
writing and the report writer.

The log readers are re-exported here (``strapdown.io.read_imu``).
"""

from strapdown.io import readers as _readers
from strapdown.io.readers import *  # noqa: F403  (the subpackage's public face)

__all__ = list(_readers.__all__)
