"""A small live plot of compliance and volume fraction per iteration (QPainter, no extra
dependency)."""
from PySide2 import QtCore, QtGui, QtWidgets


class HistoryPlot(QtWidgets.QWidget):
    def __init__(self, parent=None):
        super().__init__(parent)
        self.compliance = []
        self.volume = []
        self.setMinimumHeight(140)

    def set_history(self, compliance, volume):
        self.compliance = list(compliance)
        self.volume = list(volume)
        self.update()

    def add(self, compliance, volume):
        self.compliance.append(compliance)
        self.volume.append(volume)
        self.update()

    def _curve(self, painter, values, rect, colour, lo, hi):
        if len(values) < 2 or hi <= lo:
            return
        pen = QtGui.QPen(QtGui.QColor(colour))
        pen.setWidth(2)
        painter.setPen(pen)
        n = len(values) - 1
        points = [QtCore.QPointF(rect.left() + rect.width() * i / n,
                                 rect.bottom() - rect.height() * (v - lo) / (hi - lo))
                  for i, v in enumerate(values)]
        painter.drawPolyline(points)

    def paintEvent(self, event):
        painter = QtGui.QPainter(self)
        painter.setRenderHint(QtGui.QPainter.Antialiasing)
        painter.fillRect(self.rect(), QtGui.QColor("#ffffff"))
        rect = QtCore.QRectF(self.rect().adjusted(8, 18, -8, -8))
        painter.setPen(QtGui.QColor("#999999"))
        painter.drawRect(rect)
        if self.compliance:
            self._curve(painter, self.compliance, rect, "#2b5d8a", 0.0, max(self.compliance) * 1.05)
            self._curve(painter, self.volume, rect, "#e8a33d", 0.0, 1.0)
            painter.setPen(QtGui.QColor("#2b5d8a"))
            painter.drawText(10, 14, "compliance %.4g N·mm" % self.compliance[-1])
            painter.setPen(QtGui.QColor("#e8a33d"))
            painter.drawText(self.width() // 2 + 10, 14, "volume %.3f" % self.volume[-1])
        else:
            painter.drawText(10, 14, "history of the run")
        painter.end()
