"""XmlText writes exactly the bytes lxml would for the same tree (the SDF and URDF bodies are written as text)."""

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from lxml import etree

from worldgen.errors import SceneError
from worldgen.export.xml import XmlText, escape_attr, escape_text, fill, to_bytes

# Any text XML 1.0 can carry, with the characters that need escaping drawn often.
xml_chars = st.characters(blacklist_categories=("Cs",), blacklist_characters="\ufffe\uffff").filter(
    lambda c: c in "\t\n\r" or ord(c) >= 0x20)
xml_text = st.text(st.one_of(st.sampled_from('&<>"\'\t\n\r '), xml_chars), max_size=12)
tags = st.sampled_from(["a", "link", "pose", "geometry", "b_1"])


@st.composite
def trees(draw, depth=0):
    """(tag, [(attribute, value)], text or None, children); text and children never together (as we write)."""
    tag = draw(tags)
    names = draw(st.lists(st.sampled_from(["name", "uri", "x", "rgba"]), unique=True, max_size=3))
    attrs = [(n, draw(xml_text)) for n in names]
    if depth < 3 and draw(st.booleans()):
        return tag, attrs, None, draw(st.lists(trees(depth + 1), min_size=1, max_size=3))
    return tag, attrs, draw(st.one_of(st.none(), xml_text.filter(bool))), []


def build_lxml(parent, node):
    tag, attrs, text, children = node
    element = etree.SubElement(parent, tag, dict(attrs))
    if text is not None:
        element.text = text
    for child in children:
        build_lxml(element, child)


def write_text(out: XmlText, node):
    tag, attrs, text, children = node
    rendered = "".join(f' {k}="{escape_attr(v)}"' for k, v in attrs)
    if children:
        out.open(tag, rendered)
        for child in children:
            write_text(out, child)
        out.close(tag)
    elif text is not None:
        out.leaf(tag, escape_text(text), rendered)
    else:
        out.empty(tag, rendered)


@settings(max_examples=300, deadline=None)
@given(st.lists(trees(), min_size=1, max_size=4))
def test_xmltext_in_a_skeleton_gives_lxmls_bytes(body):
    def skeleton():
        root = etree.Element("robot", name="w")
        etree.SubElement(root, "mujoco").append(etree.Comment(" kept "))
        return root

    reference = skeleton()
    for node in body:
        build_lxml(reference, node)
    out = XmlText(depth=1)
    for node in body:
        write_text(out, node)
    root = skeleton()
    assert fill(root, root, out) == to_bytes(reference)


@pytest.mark.parametrize("bad", ["a\x00b", "bell\x07", "\x1f", "lone \ud800 surrogate", "\ufffe"])
def test_text_xml_cannot_carry_is_one_scene_error(bad):
    with pytest.raises(SceneError, match="XML cannot carry"):
        escape_attr(bad)
    with pytest.raises(SceneError, match="XML cannot carry"):
        escape_text(bad)
    with pytest.raises(ValueError):  # lxml refuses them too
        etree.Element("a", x=bad)
