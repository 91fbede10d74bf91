"""Malformed mesh files (found by fuzzing the readers) give one clear error line and exit status
1: never a crash, a hang, a huge allocation or a message spread over several lines."""

import base64
import re
import struct
import zlib

import numpy as np
import pytest

from conftest import run
from homesh import _core

TRIANGLE_XML = """<?xml version="1.0" encoding="utf-8" ?>
<NEKTAR>
  <GEOMETRY DIM="2" SPACE="3">
    <VERTEX>
      <V ID="0">0 0 0</V>
      <V ID="1">1 0 0</V>
      <V ID="2">0 1 0</V>
    </VERTEX>
    <EDGE>
      <E ID="0">0 1</E>
      <E ID="1">1 2</E>
      <E ID="2">0 2</E>
    </EDGE>
    <ELEMENT>
      <T ID="0">0 1 2</T>
    </ELEMENT>
    <CURVED>
      <E ID="0" EDGEID="0" NUMPOINTS="3" TYPE="PolyEvenlySpaced">0 0 0 0.5 0 0 1 0 0</E>
      <E ID="1" EDGEID="1" NUMPOINTS="3" TYPE="PolyEvenlySpaced">1 0 0 0.5 0.5 0 0 1 0</E>
      <E ID="2" EDGEID="2" NUMPOINTS="3" TYPE="PolyEvenlySpaced">0 0 0 0 0.5 0 0 1 0</E>
    </CURVED>
    <COMPOSITE>
      <C ID="0" NAME="Face1"> T[0] </C>
      <C ID="1" NAME="Edge2"> E[0] </C>
    </COMPOSITE>
    <DOMAIN> C[0] </DOMAIN>
  </GEOMETRY>
</NEKTAR>
"""

TRIANGLE_MSH = """$MeshFormat
2.2 0 8
$EndMeshFormat
$Nodes
6
1 0 0 0
2 X2 0 0
3 0 Y3 0
4 0.5 0 0
5 0.5 0.5 0
6 0 0.5 0
$EndNodes
$Elements
1
1 9 2 1 1 1 2 3 4 5 6
$EndElements
"""


def quality(homesh_bin, path):
    return run([homesh_bin, "quality", path, "-q"])


def assert_one_line_error(r, *phrases):
    assert r.returncode == 1, (r.returncode, r.stderr)
    assert r.stderr.startswith("homesh: error: ") and r.stderr.count("\n") == 1, r.stderr
    for phrase in phrases:
        assert phrase in r.stderr, r.stderr


def test_the_templates_are_valid(homesh_bin, tmp_path):
    (tmp_path / "t.xml").write_text(TRIANGLE_XML)
    (tmp_path / "t.msh").write_text(TRIANGLE_MSH.replace("X2", "1").replace("Y3", "1"))
    for name in ("t.xml", "t.msh"):
        r = quality(homesh_bin, tmp_path / name)
        assert r.returncode == 0, r.stderr


@pytest.mark.parametrize("edit, phrases", [
    # Entities: '&' without ';' once looped for ever; unknown ones are named on one line.
    (lambda t: t.replace('NAME="Face1"', 'NAME="a &amp b"'), ["does not start an entity"]),
    (lambda t: t.replace('NAME="Face1"', 'NAME="&x\ny;"'), ["unknown entity &x?y;"]),
    # Ids that are not ids, or refer to nothing.
    (lambda t: t.replace('<V ID="0">', '<V ID="zero">'), ['ID="zero", not an id']),
    (lambda t: t.replace('<V ID="0">', '<V ID="0\nX">'), ['ID="0?X", not an id']),
    (lambda t: t.replace('<V ID="0">', '<V ID="99999999999">'), ["not an id"]),
    (lambda t: t.replace("<T ID=\"0\">0 1 2</T>", "<T ID=\"0\">0 1 7</T>"),
     ["edge 7 is referred to but missing"]),
    (lambda t: t.replace('DIM="2"', 'DIM="abc"'), ["DIM must be 2 or 3, not 'abc'"]),
    # A composite range that once expanded to two billion ids.
    (lambda t: t.replace("E[0]", "E[0-2147483647]"), ["lists more ids than the file has"]),
    (lambda t: t.replace("E[0]", "E[5-2]"), ["runs backwards"]),
    # Numbers.
    (lambda t: t.replace('<V ID="1">1 0 0', '<V ID="1">inf 0 0'), ["not finite"]),
    (lambda t: t.replace("0.5 0.5 0 0 1 0</E>", "0.5 0.5 0 0 1</E>"),
     ["fewer than 3 coordinates"]),
    # Nesting deep enough to exhaust the stack of a recursive parser.
    (lambda t: t.replace("<DOMAIN>", "<a>" * 5000 + "</a>" * 5000 + "<DOMAIN>"),
     ["nested deeper than"]),
])
def test_malformed_nektar_xml(homesh_bin, tmp_path, edit, phrases):
    path = tmp_path / "bad.xml"
    path.write_text(edit(TRIANGLE_XML))
    assert_one_line_error(quality(homesh_bin, path), "bad.xml", *phrases)


def test_corrupt_compressed_curve_index(homesh_bin, tmp_path):
    """A compressed CURVED record whose offset points past DATAPOINTS/INDEX."""
    (tmp_path / "t.xml").write_text(TRIANGLE_XML)
    r = run([homesh_bin, "convert", tmp_path / "t.xml", "-o", tmp_path / "c.xml", "--compressed",
             "-q"])
    assert r.returncode == 0, r.stderr
    text = (tmp_path / "c.xml").read_text()
    match = re.search(r"<E>([^<]*)</E>", text)  # the edges' CurvedInfo records
    records = bytearray(zlib.decompress(base64.b64decode(match.group(1) + "==")))
    # CurvedInfo: id, entity, number of points, point set, offset, points type (int64 each).
    struct.pack_into("<q", records, 4 * 8, 10**12)
    blob = base64.b64encode(zlib.compress(bytes(records))).decode()
    path = tmp_path / "bad.xml"
    path.write_text(text.replace(match.group(1), blob))
    assert_one_line_error(quality(homesh_bin, path), "points outside DATAPOINTS/INDEX")


def test_non_finite_and_huge_coordinates(homesh_bin, tmp_path):
    path = tmp_path / "nan.msh"
    path.write_text(TRIANGLE_MSH.replace("X2", "nan").replace("Y3", "1"))
    assert_one_line_error(quality(homesh_bin, path), "a node coordinate is not a finite number")
    # Finite but near the largest double: J would overflow without the per-element scaling.
    path = tmp_path / "huge.msh"
    path.write_text(TRIANGLE_MSH.replace("X2", "1e308").replace("Y3", "1e308"))
    r = run([homesh_bin, "quality", path, "--report", "-", "-q"])
    assert r.returncode == 0, r.stderr
    assert '"invalid_elements": 1' in r.stdout  # its mid-edge nodes fold it
    # The same element scaled to unit size gives the same verdict.
    path = tmp_path / "unit.msh"
    path.write_text(TRIANGLE_MSH.replace("X2", "1e-300").replace("Y3", "1e-300"))
    r = run([homesh_bin, "quality", path, "--report", "-", "-q"])
    assert r.returncode == 0 and '"invalid_elements": 1' in r.stdout


def test_binary_msh_short_by_one_byte(homesh_bin, tmp_path):
    good = tmp_path / "good.msh"
    r = run([homesh_bin, "convert", tmp_path.parent, "-o", good])  # a directory: a clean error
    assert_one_line_error(r)
    (tmp_path / "t.msh").write_text(TRIANGLE_MSH.replace("X2", "1").replace("Y3", "1"))
    r = run([homesh_bin, "convert", tmp_path / "t.msh", "-o", good, "--binary", "-q"])
    assert r.returncode == 0, r.stderr
    data = bytearray(good.read_bytes())
    at = data.index(b"$EndNodes")
    del data[at - 5]  # one byte out of the last coordinate
    bad = tmp_path / "bad.msh"
    bad.write_bytes(bytes(data))
    assert_one_line_error(quality(homesh_bin, bad), "binary data does not end where '$EndNodes'")


def test_python_rejects_non_finite_nodes():
    nodes = np.array([[0.0, 0, 0], [1, 0, 0], [0, np.nan, 0]])
    with pytest.raises(_core.ParameterError, match="node 2 has a coordinate that is not finite"):
        _core.mesh_from_arrays(
            2, 1, nodes, np.full(3, 2, dtype=np.uint8), np.ones(3, dtype=np.int32),
            np.full((3, 2), np.nan),
            [("tri", 1, np.arange(3, dtype=np.int64).reshape(1, 3), np.ones(1, dtype=np.int32))],
            (0.0, 0.0, 1.0))
