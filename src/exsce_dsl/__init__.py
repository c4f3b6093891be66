"""exsce: executable scenarios for robot testing.

Compile scenario specifications written in the exsce DSL to W3C PROV, and
(in later layers) record, query and judge the runs of those scenarios.
"""

__version__ = "0.1.0"
