"""Input and output: gyro-log readers with validation, BROAD recordings, atomic file
writing and the report writer.

The log readers are re-exported here (``strapdown.io.read_imu``).
"""

from strapdown.io.readers import (
    RATE_PLAUSIBLE_MAX,
    ImuLog,
    UnitWarning,
    check_rows,
    csv_columns,
    read_imu,
    warn_implausible_rate,
    write_attitude,
)

__all__ = [
    "RATE_PLAUSIBLE_MAX",
    "ImuLog",
    "UnitWarning",
    "check_rows",
    "csv_columns",
    "read_imu",
    "warn_implausible_rate",
    "write_attitude",
]
