"""The Processing algorithms: a layer through a temporary GeoPackage and ``curvesmith``.

Each algorithm writes the input features' geometries (selected features only when asked)
with their row number to a temporary GeoPackage, runs the ``curvesmith`` command on it,
and writes the smoothed geometries with the input's attributes, in the input's order, to
the output. All geometry work is curvesmith's.
"""

from __future__ import annotations

import json
import os
import shlex
import shutil
import tempfile

from qgis.core import (
    QgsFeature,
    QgsFeatureRequest,
    QgsFeatureSink,
    QgsField,
    QgsFields,
    QgsGeometry,
    QgsProcessing,
    QgsProcessingAlgorithm,
    QgsProcessingException,
    QgsProcessingParameterBoolean,
    QgsProcessingParameterDefinition,
    QgsProcessingParameterEnum,
    QgsProcessingParameterFeatureSink,
    QgsProcessingParameterFeatureSource,
    QgsProcessingParameterNumber,
    QgsProcessingParameterString,
    QgsProcessingUtils,
    QgsVectorFileWriter,
    QgsVectorLayer,
    QgsWkbTypes,
)
from qgis.PyQt.QtCore import QCoreApplication, QVariant

from . import options, runner
from .icon import plugin_icon

__all__ = ["ALGORITHM_CLASSES", "CurvesmithAlgorithm"]

#: Processing setting holding the path of the ``curvesmith`` program.
CURVESMITH_PATH = "CURVESMITH_PATH"

_ROW = "curvesmith_row"
_GEOMETRY = {
    "polygon_line": [QgsProcessing.TypeVectorPolygon, QgsProcessing.TypeVectorLine],
    "polygon": [QgsProcessing.TypeVectorPolygon],
    "line": [QgsProcessing.TypeVectorLine],
}
# progress: writing the input 0-10 %, curvesmith 10-90 %, writing the output 90-100 %
_RUN_START, _RUN_END = 10.0, 90.0


def configured_path() -> str:
    """The path set in Processing > Options > Providers > curvesmith (may be empty)."""
    try:
        from processing.core.ProcessingConfig import ProcessingConfig
    except ImportError:  # Processing plugin not loaded: PATH only
        return ""
    return ProcessingConfig.getSetting(CURVESMITH_PATH) or ""


class CurvesmithAlgorithm(QgsProcessingAlgorithm):
    """A Processing algorithm that runs one ``curvesmith`` command (see :mod:`.options`)."""

    spec: options.AlgorithmSpec

    def tr(self, text: str) -> str:
        """Translate `text` in the plugin's context."""
        return QCoreApplication.translate("curvesmith", text)

    def createInstance(self):
        """A new instance of the same algorithm."""
        return type(self)()

    def name(self) -> str:
        """Algorithm id within the provider."""
        return self.spec.name

    def displayName(self) -> str:
        """Name in the toolbox."""
        return self.tr(self.spec.display_name)

    def group(self) -> str:
        """Toolbox group."""
        return self.tr("Vector smoothing")

    def groupId(self) -> str:
        """Toolbox group id."""
        return "smoothing"

    def tags(self) -> list[str]:
        """Search words."""
        return ["smooth", "smoothing", "area", "cca", "chaikin", "generalize", "coverage"]

    def icon(self):
        """The provider's icon."""
        return plugin_icon()

    def shortHelpString(self) -> str:
        """Help panel: what the algorithm does and every parameter, with its CLI option."""
        rows = [
            f"<p>{self.tr(self.spec.summary)}</p>",
            "<p>Attributes, CRS and feature order are kept; with <i>Selected features "
            "only</i> just those are smoothed. The work is done by the <code>curvesmith"
            "</code> program, found on PATH or at the path set in Processing &gt; Options "
            "&gt; Providers &gt; curvesmith.</p>",
            "<h3>Parameters</h3><dl>",
        ]
        for o in options.options_for(self.spec.name):
            default = "" if o.default is None else f" Default: <code>{o.default}</code>."
            rows.append(
                f"<dt><b>{self.tr(o.label)}</b> (<code>{o.name}</code>, CLI "
                f"<code>{o.flag}</code>)</dt><dd>{self.tr(o.help)}{default}</dd>"
            )
        rows.append("</dl>")
        return "".join(rows)

    def initAlgorithm(self, config=None):
        """Declare INPUT, the table's options (:data:`.options.OPTIONS`) and OUTPUT."""
        self.addParameter(
            QgsProcessingParameterFeatureSource(
                "INPUT", self.tr("Input layer"), _GEOMETRY[self.spec.geometry]
            )
        )
        for o in options.options_for(self.spec.name):
            param = _parameter(o, self.tr(o.label))
            if o.advanced:
                param.setFlags(param.flags() | QgsProcessingParameterDefinition.FlagAdvanced)
            param.setHelp(self.tr(o.help))
            self.addParameter(param)
        self.addParameter(QgsProcessingParameterFeatureSink("OUTPUT", self.tr("Smoothed")))

    def processAlgorithm(self, parameters, context, feedback):
        """Write the input to a GeoPackage, run curvesmith, write its result to OUTPUT."""
        source = self.parameterAsSource(parameters, "INPUT", context)
        if source is None:
            raise QgsProcessingException(self.invalidSourceError(parameters, "INPUT"))
        values = {
            o.name: _value(self, o, parameters, context)
            for o in options.options_for(self.spec.name)
        }
        try:
            executable = runner.find_curvesmith(configured_path())
        except runner.CurvesmithNotFound as exc:
            raise QgsProcessingException(str(exc)) from None
        workdir = tempfile.mkdtemp(prefix="curvesmith_", dir=QgsProcessingUtils.tempFolder())
        try:
            src_path = os.path.join(workdir, "input.gpkg")
            # FlatGeobuf: GDAL versions older than curvesmith's warn on GeoPackages it writes
            dest_path = os.path.join(workdir, "smoothed.fgb")
            feedback.setProgressText(self.tr("Writing the input for curvesmith"))
            attributes, fids, wkb_type = _write_input(source, src_path, context, feedback)
            argv = options.build_argv(executable, self.spec.name, values, src_path, dest_path)
            if fids:
                feedback.setProgressText(self.tr("Running curvesmith"))
                _run(argv, feedback)
                if options.is_batch(self.spec.name, values):
                    _report_batch_errors(dest_path + ".errors.json", fids, feedback)
                geometries = _read_output(dest_path, len(fids))
            else:
                feedback.pushWarning(self.tr("The input has no geometries to smooth"))
                geometries = {}
            feedback.setProgressText(self.tr("Writing the output"))
            dest_id = _write_output(
                self, parameters, context, feedback, source, attributes, geometries, wkb_type
            )
        except OSError as exc:
            raise QgsProcessingException(f"curvesmith: {exc}") from None
        finally:
            shutil.rmtree(workdir, ignore_errors=True)
        feedback.setProgress(100)
        return {"OUTPUT": dest_id}


def _parameter(o: options.Option, label: str):
    if o.kind == "enum":
        return QgsProcessingParameterEnum(
            o.name, label, list(o.choices), defaultValue=o.choices.index(o.default)
        )
    if o.kind == "bool":
        return QgsProcessingParameterBoolean(o.name, label, defaultValue=o.default)
    if o.kind in ("int", "float"):
        kind = (
            QgsProcessingParameterNumber.Integer
            if o.kind == "int"
            else QgsProcessingParameterNumber.Double
        )
        param = QgsProcessingParameterNumber(
            o.name, label, kind, defaultValue=o.default, optional=o.optional
        )
        if o.minimum is not None:
            param.setMinimum(o.minimum)
        return param
    return QgsProcessingParameterString(o.name, label, defaultValue=o.default, optional=o.optional)


def _value(alg, o: options.Option, parameters, context):
    """A parameter's value, or None when an optional one is left empty."""
    if o.optional and parameters.get(o.name) in (None, ""):
        return None
    if o.kind == "enum":
        return alg.parameterAsEnum(parameters, o.name, context)
    if o.kind == "bool":
        return alg.parameterAsBoolean(parameters, o.name, context)
    if o.kind == "int":
        return alg.parameterAsInt(parameters, o.name, context)
    if o.kind == "float":
        return alg.parameterAsDouble(parameters, o.name, context)
    return alg.parameterAsString(parameters, o.name, context)


def _write_input(source, path, context, feedback):
    """Write the source's geometries, each with its row number, to a GeoPackage.

    Returns the attributes of every row (in source order), the feature id of every
    geometry written (in file order), and the geometry type (curves made linear:
    curvesmith reads polylines).
    Features without geometry are not written; they keep their (empty) geometry.
    """
    wkb_type = source.wkbType()
    linear = QgsWkbTypes.linearType(wkb_type)
    fields = QgsFields()
    fields.append(QgsField(_ROW, QVariant.LongLong))
    opts = QgsVectorFileWriter.SaveVectorOptions()
    opts.driverName = "GPKG"
    opts.layerName = "input"
    opts.fileEncoding = "UTF-8"
    writer = QgsVectorFileWriter.create(
        path, fields, linear, source.sourceCrs(), context.transformContext(), opts
    )
    if writer.hasError() != QgsVectorFileWriter.NoError:
        raise QgsProcessingException(f"cannot write {path}: {writer.errorMessage()}")
    total = max(source.featureCount(), 1)
    attributes, fids = [], []
    for i, feat in enumerate(source.getFeatures(QgsFeatureRequest())):
        if feedback.isCanceled():
            del writer
            raise QgsProcessingException("curvesmith: cancelled, no output written")
        attributes.append(feat.attributes())
        geom = feat.geometry()
        if geom.isNull() or geom.isEmpty():
            continue
        if QgsWkbTypes.isCurvedType(geom.wkbType()):
            geom = QgsGeometry(geom.constGet().segmentize())
        out = QgsFeature(fields)
        out.setGeometry(geom)
        out.setAttributes([len(attributes) - 1])
        if not writer.addFeature(out, QgsFeatureSink.FastInsert):
            raise QgsProcessingException(f"cannot write {path}: {writer.errorMessage()}")
        fids.append(feat.id())
        feedback.setProgress(_RUN_START * (i + 1) / total)
    del writer  # closes the file
    return attributes, fids, linear


def _run(argv, feedback):
    """Run curvesmith; its messages go to the log, its progress bar to the progress."""
    feedback.pushCommandInfo(" ".join(shlex.quote(a) for a in argv))

    def on_line(stream, line):
        if line.startswith("Warning:"):
            feedback.pushWarning(line)
        elif not line.startswith("Error:"):  # the error becomes the exception
            feedback.pushConsoleInfo(line)

    def on_progress(pct):
        feedback.setProgress(_RUN_START + (_RUN_END - _RUN_START) * pct / 100.0)

    try:
        result = runner.run_cli(
            argv, is_canceled=feedback.isCanceled, on_progress=on_progress, on_line=on_line
        )
    except runner.Cancelled as exc:
        raise QgsProcessingException(f"curvesmith: {exc}") from None
    if result.returncode != 0:
        raise QgsProcessingException(f"curvesmith: {runner.error_message(result, argv[0])}")
    feedback.setProgress(_RUN_END)


def _report_batch_errors(path, fids, feedback):
    """Batch mode: every feature curvesmith left unchanged, with its reason, as a warning."""
    try:
        with open(path, encoding="utf-8") as f:
            errors = json.load(f)
    except (OSError, ValueError):
        feedback.pushWarning(f"curvesmith wrote no readable errors report ({path})")
        return
    for e in errors:
        feedback.pushWarning(f"feature {fids[e['index']]} left unchanged: {e['reason']}")


def _read_output(path, expected):
    """Row number -> smoothed geometry, from curvesmith's output file."""
    layer = QgsVectorLayer(path, "smoothed", "ogr")
    if not layer.isValid():
        raise QgsProcessingException(f"curvesmith wrote no readable output ({path})")
    row = layer.fields().indexOf(_ROW)
    if row < 0:
        raise QgsProcessingException(f"curvesmith's output lost the {_ROW} column ({path})")
    geometries = {int(f.attributes()[row]): f.geometry() for f in layer.getFeatures()}
    if len(geometries) != expected:
        raise QgsProcessingException(
            f"curvesmith wrote {len(geometries)} features for {expected} input features"
        )
    return geometries


def _output_suffix(alg, parameters, context) -> str:
    """The output file's suffix (``""`` for a memory layer)."""
    dest = alg.parameterAsOutputLayer(parameters, "OUTPUT", context) or ""
    return os.path.splitext(dest.split("|")[0])[1].lower()


def _feature_id_fields(alg, parameters, context) -> list[int]:
    """Fields holding the input file's feature ids (a GeoPackage's ``fid``), not its data.

    An output file of another format would get them as an ordinary column (a
    Shapefile's float ``fid``); the input's own attributes are the others.
    """
    suffix = _output_suffix(alg, parameters, context)
    if not suffix or suffix in (".gpkg", ".sqlite"):  # memory layers, GeoPackages: kept
        return []
    layer = alg.parameterAsVectorLayer(parameters, "INPUT", context)
    if layer is None or layer.providerType() != "ogr":
        return []
    return sorted(int(i) for i in layer.primaryKeyAttributes())


def _write_output(alg, parameters, context, feedback, source, attributes, geometries, wkb_type):
    """Write every input row, with its attributes and smoothed geometry, to OUTPUT."""
    if not QgsWkbTypes.isMultiType(wkb_type) and any(g.isMultipart() for g in geometries.values()):
        wkb_type = QgsWkbTypes.multiType(wkb_type)
    fields = source.fields()
    drop = _feature_id_fields(alg, parameters, context)
    shapefile = _output_suffix(alg, parameters, context) == ".shp"
    if drop or shapefile:
        kept = [i for i in range(fields.count()) if i not in drop]
        fields = QgsFields()
        for i in kept:
            field = QgsField(source.fields().at(i))
            if shapefile and field.type() == QVariant.LongLong and not 0 < field.length() <= 18:
                field.setLength(18)  # GDAL reads a wider N(20, 0) column back as Real
            fields.append(field)
        attributes = [[attrs[i] for i in kept] for attrs in attributes]
    sink, dest_id = alg.parameterAsSink(
        parameters, "OUTPUT", context, fields, wkb_type, source.sourceCrs()
    )
    if sink is None:
        raise QgsProcessingException(alg.invalidSinkError(parameters, "OUTPUT"))
    multi = QgsWkbTypes.isMultiType(wkb_type)
    span = 100.0 - _RUN_END
    for i, attrs in enumerate(attributes):
        feat = QgsFeature(fields)
        feat.setAttributes(attrs)
        geom = geometries.get(i)
        if geom is not None:
            if multi and not geom.isMultipart():
                geom.convertToMultiType()
            feat.setGeometry(geom)
        if not sink.addFeature(feat, QgsFeatureSink.FastInsert):
            raise QgsProcessingException(alg.writeFeatureError(sink, parameters, "OUTPUT"))
        feedback.setProgress(_RUN_END + span * (i + 1) / len(attributes))
    return dest_id


def _algorithm_class(spec: options.AlgorithmSpec):
    return type(f"Curvesmith_{spec.name}", (CurvesmithAlgorithm,), {"spec": spec})


#: One class per :data:`.options.ALGORITHMS` entry.
ALGORITHM_CLASSES = tuple(_algorithm_class(spec) for spec in options.ALGORITHMS)
