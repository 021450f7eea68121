"""The live plot of a run (QPainter, no extra dependency): compliance (left axis, N·mm) and
volume fraction (right axis, 0 to 1) per iteration (bottom axis), each curve with its own
legend line above the axes, so that neither covers the other whatever the panel's width."""
import math

from PySide import QtCore, QtGui

COMPLIANCE_COLOUR = "#2b5d8a"
VOLUME_COLOUR = "#d08a1e"


def nice_ticks(high, count=4):
    """About `count` round tick values from 0 to at least `high` (1, 2 or 5 times a power of ten
    apart); returns (ticks, top)."""
    if not high > 0 or not math.isfinite(high):
        return [0.0, 1.0], 1.0
    raw = high / count
    power = 10 ** math.floor(math.log10(raw))
    step = next(m * power for m in (1, 2, 5, 10) if m * power >= raw)
    top = step * math.ceil(high / step)
    return [step * i for i in range(int(round(top / step)) + 1)], top


def _text_width(metrics, text):
    """Width of `text` in pixels (Qt 5.11+ and 6 call it horizontalAdvance)."""
    advance = getattr(metrics, "horizontalAdvance", None)
    return advance(text) if advance else metrics.width(text)


def _label(value):
    return "%g" % float("%.3g" % value)


class HistoryPlot(QtGui.QWidget):
    def __init__(self, parent=None):
        super().__init__(parent)
        self.compliance = []
        self.volume = []
        self.setMinimumHeight(170)
        self.setSizePolicy(QtGui.QSizePolicy.Ignored, QtGui.QSizePolicy.Preferred)

    def set_history(self, compliance, volume):
        self.compliance = list(compliance)
        self.volume = list(volume)
        self.update()

    def add(self, compliance, volume):
        self.compliance.append(compliance)
        self.volume.append(volume)
        self.update()

    def legend_lines(self):
        """The two legend texts, one per curve."""
        c = "compliance: %.4g N·mm" % self.compliance[-1] if self.compliance else "compliance (N·mm)"
        v = "volume fraction: %.3f" % self.volume[-1] if self.volume else "volume fraction"
        return c, v

    def plot_rect(self, metrics, tick_labels=("0000",)):
        """The axes' rectangle inside the widget: room for two legend lines above, the left
        tick labels (the widest of `tick_labels`), the right ones and the iteration labels below."""
        line = metrics.height()
        left = max(_text_width(metrics, t) for t in tick_labels) + 8
        right = _text_width(metrics, "0.0") + 8
        return QtCore.QRectF(left, 2 * line + 8, max(10, self.width() - left - right),
                             max(10, self.height() - 3 * line - 16))

    def _curve(self, painter, values, rect, colour, top, count):
        if len(values) < 1 or top <= 0:
            return
        pen = QtGui.QPen(QtGui.QColor(colour))
        pen.setWidth(2)
        painter.setPen(pen)
        span = max(1, count - 1)
        points = [QtCore.QPointF(rect.left() + rect.width() * i / span,
                                 rect.bottom() - rect.height() * min(1.0, max(0.0, v / top)))
                  for i, v in enumerate(values)]
        if len(points) == 1:
            painter.drawEllipse(points[0], 2, 2)
        else:
            painter.drawPolyline(points)

    def _legend(self, painter, metrics):
        for row, (text, colour) in enumerate(zip(self.legend_lines(), (COMPLIANCE_COLOUR, VOLUME_COLOUR))):
            y = 4 + row * metrics.height()
            painter.setPen(QtGui.QPen(QtGui.QColor(colour), 3))
            painter.drawLine(6, y + metrics.ascent() // 2 + 1, 22, y + metrics.ascent() // 2 + 1)
            painter.setPen(QtGui.QColor("#222222"))
            painter.drawText(28, y + metrics.ascent(), text)

    def _axes(self, painter, metrics, rect, c_ticks, c_top, count):
        painter.setPen(QtGui.QColor("#888888"))
        painter.drawRect(rect)
        for t in c_ticks:  # left: compliance
            y = rect.bottom() - rect.height() * t / c_top
            painter.setPen(QtGui.QColor("#e4e4e4"))
            painter.drawLine(QtCore.QPointF(rect.left() + 1, y), QtCore.QPointF(rect.right() - 1, y))
            painter.setPen(QtGui.QColor(COMPLIANCE_COLOUR))
            text = _label(t)
            painter.drawText(QtCore.QRectF(0, y - metrics.height() / 2, rect.left() - 4, metrics.height()),
                             QtCore.Qt.AlignRight | QtCore.Qt.AlignVCenter, text)
        painter.setPen(QtGui.QColor(VOLUME_COLOUR))
        for v in (0.0, 0.5, 1.0):  # right: volume fraction
            y = rect.bottom() - rect.height() * v
            painter.drawText(QtCore.QRectF(rect.right() + 4, y - metrics.height() / 2, 60, metrics.height()),
                             QtCore.Qt.AlignLeft | QtCore.Qt.AlignVCenter, "%.1f" % v)
        painter.setPen(QtGui.QColor("#444444"))
        bottom = rect.bottom() + 4
        painter.drawText(QtCore.QRectF(rect.left(), bottom, rect.width(), metrics.height()),
                         QtCore.Qt.AlignLeft, "1")
        painter.drawText(QtCore.QRectF(rect.left(), bottom, rect.width(), metrics.height()),
                         QtCore.Qt.AlignHCenter, "iteration")
        painter.drawText(QtCore.QRectF(rect.left(), bottom, rect.width(), metrics.height()),
                         QtCore.Qt.AlignRight, str(max(1, count)))

    def paintEvent(self, event):
        painter = QtGui.QPainter(self)
        painter.setRenderHint(QtGui.QPainter.Antialiasing)
        painter.fillRect(self.rect(), QtGui.QColor("#ffffff"))
        metrics = painter.fontMetrics()
        count = len(self.compliance)
        c_ticks, c_top = nice_ticks(max(self.compliance) if self.compliance else 0.0)
        rect = self.plot_rect(metrics, [_label(t) for t in c_ticks])
        self._legend(painter, metrics)
        self._axes(painter, metrics, rect, c_ticks, c_top, count)
        self._curve(painter, self.compliance, rect, COMPLIANCE_COLOUR, c_top, count)
        self._curve(painter, self.volume, rect, VOLUME_COLOUR, 1.0, count)
        painter.end()
