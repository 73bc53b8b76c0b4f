"""What every XML exporter shares: safe parsing, the template skeletons, stable bytes."""

from __future__ import annotations

from importlib import resources

from lxml import etree

__all__ = ["safe_parser", "parse_bytes", "load_template", "to_bytes", "sub"]


def safe_parser() -> etree.XMLParser:
    """An lxml parser that resolves no entities and never touches the network."""
    return etree.XMLParser(resolve_entities=False, no_network=True, remove_blank_text=True, load_dtd=False, huge_tree=False)


def parse_bytes(data: bytes) -> etree._ElementTree:
    return etree.ElementTree(etree.fromstring(data, safe_parser()))


def load_template(name: str) -> etree._ElementTree:
    """A fresh copy of the skeleton ``templates/<name>``."""
    data = resources.files("worldgen.templates").joinpath(name).read_bytes()
    return parse_bytes(data)


def to_bytes(tree) -> bytes:
    """UTF-8 bytes with a declaration, two-space indentation and a final newline."""
    root = tree.getroot() if hasattr(tree, "getroot") else tree
    etree.indent(root, space="  ")
    return etree.tostring(root, pretty_print=True, xml_declaration=True, encoding="UTF-8")


def sub(parent, tag: str, text: str | None = None, **attrs) -> etree._Element:
    """Append ``<tag attrs>text</tag>`` to ``parent``; attribute order is as given."""
    el = etree.SubElement(parent, tag, attrs)
    if text is not None:
        el.text = text
    return el
