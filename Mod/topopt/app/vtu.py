"""VTK's XML unstructured grid (.vtu) for linear tets, written from numpy arrays: the form in
which a run's fields reach FreeCAD FEM (a FEM mesh reads its tets from it, a post-processing
pipeline its fields). ASCII, which every VTK reader takes."""
import numpy as np

_VTK_TETRA = 10


def _data_array(name, values, components):
    values = np.asarray(values, dtype=np.float64).reshape(-1)
    text = " ".join("%.9g" % v for v in values)
    return ('        <DataArray type="Float64" Name="%s" NumberOfComponents="%d" format="ascii">%s</DataArray>\n'
            % (name, components, text))


def write_tets(path, nodes, tets, point_fields=(), cell_fields=()):
    """Writes the tet mesh `nodes` (#V x 3, mm) / `tets` (#T x 4, 0-based) to `path` with
    fields: point_fields and cell_fields are (name, values) with values #V or #T (scalars)
    or #V x 3 / #T x 3 (vectors)."""
    nodes = np.asarray(nodes, dtype=np.float64).reshape(-1, 3)
    tets = np.asarray(tets, dtype=np.int64).reshape(-1, 4)
    parts = ['<?xml version="1.0"?>\n',
             '<VTKFile type="UnstructuredGrid" version="0.1" byte_order="LittleEndian">\n',
             '  <UnstructuredGrid>\n',
             '    <Piece NumberOfPoints="%d" NumberOfCells="%d">\n' % (len(nodes), len(tets))]
    for tag, fields, count in (("PointData", point_fields, len(nodes)), ("CellData", cell_fields, len(tets))):
        parts.append("      <%s>\n" % tag)
        for name, values in fields:
            values = np.asarray(values, dtype=np.float64)
            components = 1 if values.ndim == 1 else values.shape[1]
            if values.shape[0] != count:
                raise ValueError("field %s has %d rows for %d %s" % (name, values.shape[0], count, tag))
            parts.append(_data_array(name, values, components))
        parts.append("      </%s>\n" % tag)
    parts.append("      <Points>\n")
    parts.append(_data_array("Points", nodes, 3))
    parts.append("      </Points>\n      <Cells>\n")
    parts.append('        <DataArray type="Int64" Name="connectivity" format="ascii">%s</DataArray>\n'
                 % " ".join(map(str, tets.reshape(-1).tolist())))
    parts.append('        <DataArray type="Int64" Name="offsets" format="ascii">%s</DataArray>\n'
                 % " ".join(map(str, range(4, 4 * len(tets) + 1, 4))))
    parts.append('        <DataArray type="UInt8" Name="types" format="ascii">%s</DataArray>\n'
                 % " ".join([str(_VTK_TETRA)] * len(tets)))
    parts.append("      </Cells>\n    </Piece>\n  </UnstructuredGrid>\n</VTKFile>\n")
    with open(path, "w") as f:
        f.write("".join(parts))
    return path


def _array(element):
    """The numbers of an ASCII DataArray element, shaped #rows x NumberOfComponents (flat for
    one component)."""
    if element.get("format", "ascii") != "ascii":
        raise ValueError("DataArray %s is not ASCII" % element.get("Name"))
    values = np.array((element.text or "").split(), dtype=np.float64)
    components = int(element.get("NumberOfComponents", "1"))
    return values.reshape(-1, components) if components > 1 else values


def read_tets(path):
    """Reads an ASCII .vtu of linear tets (as write_tets and the core write them). Returns
    (nodes #V x 3, tets #T x 4 0-based, {point field: array}, {cell field: array}). Raises
    ValueError when the file holds other cells or no piece."""
    import xml.etree.ElementTree as ET
    piece = ET.parse(path).getroot().find("UnstructuredGrid/Piece")
    if piece is None:
        raise ValueError("%s holds no unstructured grid" % path)
    nodes = _array(piece.find("Points/DataArray")).reshape(-1, 3)
    cells = {a.get("Name"): a for a in piece.findall("Cells/DataArray")}
    if np.any(_array(cells["types"]) != _VTK_TETRA):
        raise ValueError("%s holds cells other than linear tets" % path)
    tets = _array(cells["connectivity"]).astype(np.int64).reshape(-1, 4)
    fields = []
    for tag in ("PointData", "CellData"):
        fields.append({a.get("Name"): _array(a) for a in piece.findall(tag + "/DataArray")})
    return nodes, tets, fields[0], fields[1]
