"""curvesmith for QGIS: a Processing provider that runs the ``curvesmith`` program.

QGIS calls :func:`classFactory`; the Processing framework then finds the provider
``curvesmith`` with the algorithms ``curvesmith:smooth``, ``curvesmith:smoothcoverage``
and ``curvesmith:smoothnetwork``. Headless (scripts, ``qgis_process``, tests)::

    plugin = classFactory(None)
    plugin.initProcessing()
"""


def classFactory(iface):
    """Return the plugin for QGIS (`iface` may be None when there is no GUI)."""
    from .plugin import CurvesmithPlugin

    return CurvesmithPlugin(iface)
