"""Run curvesmith's Processing algorithms in a real, headless QGIS (QGIS's own Python).

Usage: ``python3 run_scenarios.py SPEC.json RESULTS.json`` with the system Python that
has ``qgis`` (``tests/test_qgis_plugin.py`` starts it). SPEC holds the plugin folder and a
list of scenarios; RESULTS gets, per scenario, whether it ran, the error it reported, the
log, the progress values and where the output was written (a temporary layer is saved to
a GeoPackage so that the tests can read it). The checks themselves are in the tests.
"""

import json
import os
import sys
import threading
import time
import traceback

os.environ.setdefault("QT_QPA_PLATFORM", "offscreen")

from qgis.core import (
    QgsApplication,
    QgsCoordinateTransformContext,
    QgsFeature,
    QgsGeometry,
    QgsProcessingAlgRunnerTask,
    QgsProcessingContext,
    QgsProcessingFeatureSourceDefinition,
    QgsProcessingFeedback,
    QgsProject,
    QgsVectorFileWriter,
    QgsVectorLayer,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QCoreApplication


class RecordingFeedback(QgsProcessingFeedback):
    """A feedback that keeps every message and progress value."""

    def __init__(self):
        super().__init__()
        self.log, self.errors, self.progress = [], [], []
        self.command_given = threading.Event()  # the algorithm is about to start curvesmith
        self.progressChanged.connect(self.progress.append)

    def pushInfo(self, text):
        self.log.append(["info", text])

    def pushCommandInfo(self, text):
        self.log.append(["command", text])
        self.command_thread = threading.get_ident()  # the algorithm's thread
        self.command_given.set()

    def pushConsoleInfo(self, text):
        self.log.append(["console", text])

    def pushDebugInfo(self, text):
        self.log.append(["debug", text])

    def pushWarning(self, text):
        self.log.append(["warning", text])

    def reportError(self, text, fatalError=False):
        self.errors.append(text)


def descendants(pid):
    """Process ids of every live descendant of `pid` (from /proc)."""
    parent = {}
    for entry in os.listdir("/proc"):
        if entry.isdigit():
            try:
                with open(f"/proc/{entry}/stat") as f:
                    fields = f.read().rsplit(")", 1)[1].split()
            except OSError:
                continue
            if fields[0] != "Z":
                parent[int(entry)] = int(fields[1])
    found, frontier = [], [pid]
    while frontier:
        p = frontier.pop()
        kids = [c for c, pp in parent.items() if pp == p]
        found += kids
        frontier += kids
    return found


def alive(pids):
    """The ones of `pids` still running (not gone, not zombies)."""
    out = []
    for p in pids:
        try:
            with open(f"/proc/{p}/stat") as f:
                if f.read().rsplit(")", 1)[1].split()[0] != "Z":
                    out.append(p)
        except OSError:
            pass
    return out


def save(layer, path):
    """Write a (temporary) layer to a GeoPackage."""
    opts = QgsVectorFileWriter.SaveVectorOptions()
    opts.driverName = "GPKG"
    err = QgsVectorFileWriter.writeAsVectorFormatV3(
        layer, path, QgsCoordinateTransformContext(), opts
    )
    if err[0] != QgsVectorFileWriter.NoError:
        raise RuntimeError(f"cannot save {layer.name()} to {path}: {err}")


def describe(layer):
    """What the tests check on the QGIS side: provider, CRS, type, fields, count."""
    return {
        "provider": layer.providerType(),
        "crs": layer.crs().authid(),
        "wkb_type": QgsWkbTypes.displayString(layer.wkbType()),
        "fields": [[f.name(), f.typeName()] for f in layer.fields()],
        "count": layer.featureCount(),
    }


def run_as_task(registry, algorithm, params, fb, res):
    """Run as the algorithm dialog does: a task on QGIS's task manager, in a worker thread."""
    alg = registry.createAlgorithmById(algorithm)
    context = QgsProcessingContext()
    context.setProject(QgsProject.instance())
    task = QgsProcessingAlgRunnerTask(alg, params, context, fb)
    done = {}
    task.executed.connect(lambda ok, results: done.update(ok=ok, results=results))
    QgsApplication.taskManager().addTask(task)
    deadline = time.monotonic() + 300
    while "ok" not in done and time.monotonic() < deadline:
        QCoreApplication.processEvents()
        time.sleep(0.01)
    if not done.get("ok"):
        raise RuntimeError(f"the task failed: {fb.errors}")
    res["worker"] = fb.command_thread != threading.get_ident()
    return done["results"]


def run_scenario(sc, processing, registry):
    """Run one scenario; return what happened."""
    from processing.core.ProcessingConfig import ProcessingConfig

    # set directly: the options dialog's validator refuses a path that does not exist,
    # but a saved path can go stale (an environment deleted later)
    ProcessingConfig.settings["CURVESMITH_PATH"].value = sc.get("setting_path", "")
    old_path = os.environ["PATH"]
    if "path_env" in sc:
        os.environ["PATH"] = sc["path_env"]
    params = dict(sc["params"])
    if "memory" in sc:  # a temporary layer made from WKT: [attribute, WKT] rows
        layer = QgsVectorLayer(sc["memory"]["uri"], "input", "memory")
        for value, wkt in sc["memory"]["features"]:
            feat = QgsFeature(layer.fields())
            feat.setAttributes([value])
            feat.setGeometry(QgsGeometry.fromWkt(wkt))
            layer.dataProvider().addFeature(feat)
    else:
        layer = QgsVectorLayer(sc["input"], "input", "ogr")
    if not layer.isValid():
        raise RuntimeError(f"cannot open {sc['input']}")
    QgsProject.instance().addMapLayer(layer)
    if "select_fids" in sc:
        layer.selectByIds(sc["select_fids"])
        params["INPUT"] = QgsProcessingFeatureSourceDefinition(layer.id(), True)
    else:
        params["INPUT"] = layer.id()
    fb = RecordingFeedback()
    res = {"ok": False, "error": None}
    canceller, finished = None, threading.Event()
    if "cancel_after" in sc:
        # cancel `cancel_after` seconds after curvesmith was started, as a user would

        def cancel():
            if fb.command_given.wait(120):
                time.sleep(sc["cancel_after"])
                if finished.is_set():
                    return
                res["descendants"] = descendants(os.getpid())
                res["cancelled_at"] = time.monotonic() - start
                fb.cancel()

        canceller = threading.Thread(target=cancel, daemon=True)
    start = time.monotonic()
    if canceller is not None:
        canceller.start()
    try:
        if sc.get("gui_like"):
            # as the algorithm dialog runs it: exceptions caught, reported to the feedback
            alg = registry.createAlgorithmById(sc["algorithm"])
            context = QgsProcessingContext()
            context.setProject(QgsProject.instance())
            results, ok = alg.run(params, context, fb)
            res["ok"] = bool(ok)
        else:
            if sc.get("as_task"):
                results = run_as_task(registry, sc["algorithm"], params, fb, res)
            else:
                results = processing.run(sc["algorithm"], params, feedback=fb)
            res["ok"] = True
            out = results["OUTPUT"]
            if isinstance(out, str):
                out = QgsVectorLayer(out, "output", "ogr")
            res["output_layer"] = describe(out)
            if out.providerType() == "memory":
                path = sc["save_temporary_to"]
                save(out, path)
                res["output"] = path
            else:
                res["output"] = out.source().split("|")[0]
    except Exception as exc:
        res["error"] = str(exc)
        res["error_type"] = type(exc).__name__
        res["traceback"] = traceback.format_exc()
    finally:
        res["elapsed"] = time.monotonic() - start
        if canceller is not None:
            finished.set()
            fb.command_given.set()  # a run that failed before curvesmith: let the thread end
            canceller.join()
        os.environ["PATH"] = old_path
        QgsProject.instance().removeMapLayer(layer.id())
    if "descendants" in res:  # SIGKILL is delivered asynchronously: give it 5 s
        deadline = time.monotonic() + 5
        while alive(res["descendants"]) and time.monotonic() < deadline:
            time.sleep(0.05)
        res["alive_after"] = alive(res["descendants"])
    res["log"], res["reported_errors"], res["progress"] = fb.log, fb.errors, fb.progress
    return res


def describe_provider(registry):
    """The provider's algorithms and their parameters, as the toolbox shows them."""
    provider = registry.providerById("curvesmith")
    out = {"id": provider.id(), "name": provider.name(), "algorithms": {}}
    for alg in provider.algorithms():
        out["algorithms"][alg.id()] = {
            "display_name": alg.displayName(),
            "help": alg.shortHelpString(),
            "parameters": [
                {
                    "name": p.name(),
                    "type": p.type(),
                    "default": p.defaultValue(),
                    "optional": bool(p.flags() & p.FlagOptional),
                    "advanced": bool(p.flags() & p.FlagAdvanced),
                    "help": p.help(),
                }
                for p in alg.parameterDefinitions()
            ],
        }
    return out


def main(spec_path, results_path):
    with open(spec_path) as f:
        spec = json.load(f)
    QgsApplication.setPrefixPath("/usr", True)
    app = QgsApplication([], False)
    app.initQgis()
    sys.path.append(spec.get("processing_plugins", "/usr/share/qgis/python/plugins"))
    from processing.core.Processing import Processing

    Processing.initialize()
    import processing

    sys.path.insert(0, spec["plugin_parent"])
    import curvesmith_qgis

    plugin = curvesmith_qgis.classFactory(None)
    plugin.initProcessing()
    registry = QgsApplication.processingRegistry()
    results = {"provider": describe_provider(registry), "scenarios": {}}
    for sc in spec["scenarios"]:
        results["scenarios"][sc["name"]] = run_scenario(sc, processing, registry)
    plugin.unload()
    results["unloaded"] = registry.providerById("curvesmith") is None
    with open(results_path, "w") as f:
        json.dump(results, f, indent=1, default=str)
    app.exitQgis()


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
