"""The QGIS-side scripts run under QGIS's own Python: pytest must not import them."""

collect_ignore = ["run_scenarios.py"]
