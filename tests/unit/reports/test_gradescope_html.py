"""Gradescope's html output against the sanitiser rules we could find.

Gradescope's specification (gradescope/autograder_samples docs/specs.md,
"Output String Formatting") says only: "html" renders HTML, "we sanitize
the output so you may not be able to use all HTML elements"; it lists no
elements. Gradescope is a Rails application, and the rules below are what
Rails' own sanitiser keeps by default, copied by hand from its sources (an
assumption about Gradescope's settings that nothing on Gradescope's side
confirms):
- elements and attributes: rails-html-sanitizer, lib/rails/html/sanitizer.rb
  (DEFAULT_ALLOWED_TAGS, DEFAULT_ALLOWED_ATTRIBUTES; commit ee27f74);
- URIs in src and href: Loofah's allowed_uri? (lib/loofah/html5/scrub.rb):
  a scheme from its protocol list, and for data: only the media types of
  ACCEPTABLE_URI_DATA_MEDIATYPES (lib/loofah/html5/safelist.rb; 2706d7e).
An output that keeps to these rules comes through such a sanitiser unchanged.
"""
from __future__ import annotations

import base64
import io
from html.parser import HTMLParser

import pytest
from PIL import Image

from grader.reports import gradescope_json
from test_reports import make_diagnosed, make_perfect

RAILS_TAGS = {
    "a", "abbr", "acronym", "address", "b", "big", "blockquote", "br", "cite", "code", "dd", "del", "dfn",
    "div", "dl", "dt", "em", "h1", "h2", "h3", "h4", "h5", "h6", "hr", "i", "img", "ins", "kbd", "li", "mark",
    "ol", "p", "pre", "samp", "small", "span", "strong", "sub", "sup", "time", "tt", "ul", "var"}
RAILS_ATTRIBUTES = {"abbr", "alt", "cite", "class", "datetime", "height", "href", "lang", "name", "src", "title",
                    "width", "xml:lang"}
# The schemes a picture or a link could use here (Loofah's list is longer;
# javascript: is not on it).
LOOFAH_PROTOCOLS = {"http", "https", "mailto", "data"}
LOOFAH_DATA_MEDIATYPES = {"image/gif", "image/jpeg", "image/png", "text/css", "text/plain"}


class _Markup(HTMLParser):
    def __init__(self):
        super().__init__(convert_charrefs=True)
        self.tags: list[str] = []
        self.attributes: list[tuple[str, str, str]] = []

    def handle_starttag(self, tag, attrs):
        self.tags.append(tag)
        self.attributes += [(tag, name, value or "") for name, value in attrs]


def breaches(html: str) -> list[str]:
    """What a Rails-default sanitiser would remove from `html`."""
    markup = _Markup()
    markup.feed(html)
    found = [f"element <{t}>" for t in markup.tags if t not in RAILS_TAGS]
    for tag, name, value in markup.attributes:
        if name not in RAILS_ATTRIBUTES:
            found.append(f"attribute {name} on <{tag}>")
        elif name in ("src", "href") and ":" in value.split("/", 1)[0]:
            scheme = value.split(":", 1)[0].lower()
            mediatype = value[len("data:"):].split(";", 1)[0].split(",", 1)[0].lower()
            if scheme not in LOOFAH_PROTOCOLS or (scheme == "data" and mediatype not in LOOFAH_DATA_MEDIATYPES):
                found.append(f"URI {value[:30]} in {name}")
    return found


def test_the_rules_catch_what_a_sanitiser_removes():
    """The checker is not vacuous: the markup this output used before
    (figure, figcaption, style) and a script URI are each caught."""
    old = ('<div><figure style="display:inline-block"><img src="data:image/png;base64,AAAA" alt="x" '
           'style="image-rendering:pixelated"><figcaption>x</figcaption></figure></div>')
    assert breaches(old) == ["element <figure>", "element <figcaption>", "attribute style on <figure>",
                             "attribute style on <img>"]
    assert breaches('<a href="javascript:alert(1)">x</a>') == ["URI javascript:alert(1) in href"]
    assert breaches('<img src="data:image/svg+xml;base64,AAAA">') == ["URI data:image/svg+xml;base64,AAAA in src"]


@pytest.mark.parametrize("make", [make_diagnosed, make_perfect])
def test_the_html_output_keeps_to_the_rails_default_rules(make, tmp_path):
    result = make(tmp_path) if make is make_diagnosed else make()
    data = gradescope_json.results_json(result, output_format="html")
    assert data["output_format"] == "html"
    assert breaches(data["output"]) == []


def test_the_pictures_are_png_data_uris_that_decode(tmp_path):
    """Both pictures survive the rules as PNG data URIs, after the whole
    summary (a sanitiser that drops them takes no text with them)."""
    html = gradescope_json.results_json(make_diagnosed(tmp_path), output_format="html")["output"]
    markup = _Markup()
    markup.feed(html)
    sources = [value for tag, name, value in markup.attributes if tag == "img" and name == "src"]
    assert len(sources) == 2
    for source in sources:
        assert source.startswith("data:image/png;base64,")
        Image.open(io.BytesIO(base64.b64decode(source.split(",", 1)[1]))).verify()
    assert markup.tags[-2:] == ["img", "img"]
    assert html.index("<img") > html.rindex("What to do:")
