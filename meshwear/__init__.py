"""meshwear: wear of rigid triangle-mesh bodies, exported as VTK time series."""

__version__ = "0.1.0"
