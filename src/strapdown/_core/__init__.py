"""Internal foundations shared by every layer: input validation, the float64/mpmath
arithmetic backends and the small-angle series. Imports nothing else of strapdown."""
