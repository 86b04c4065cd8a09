"""Names that cannot pass for others: seat-label look-alikes refused, look-alike names made distinct."""

from __future__ import annotations

import unicodedata

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from test_server import RawClient, clients, make_server  # noqa: F401  (fixtures)

from airtable.net import protocol as proto
from airtable.net.names import distinct_name, looks_like_label, skeleton

# Written apart from names.py: Latin letters and the Cyrillic or Greek letters that pass for them,
# by their Unicode names (checked below), as a reader of the projector would confuse them.
LOOK_ALIKES = {
    "a": ["\u0430", "\u03b1"],  # CYRILLIC SMALL LETTER A, GREEK SMALL LETTER ALPHA
    "c": ["\u0441"],
    "e": ["\u0435"],
    "o": ["\u043e", "\u03bf"],
    "p": ["\u0440", "\u03c1"],
    "x": ["\u0445"],
    "y": ["\u0443"],
    "s": ["\u0455"],
    "A": ["\u0410", "\u0391"],
    "B": ["\u0412", "\u0392"],
    "C": ["\u0421"],
    "E": ["\u0415", "\u0395"],
    "H": ["\u041d", "\u0397"],
    "K": ["\u041a", "\u039a"],
    "M": ["\u041c", "\u039c"],
    "O": ["\u041e", "\u039f"],
    "P": ["\u0420", "\u03a1"],
    "S": ["\u0405"],
    "T": ["\u0422", "\u03a4"],
    "X": ["\u0425", "\u03a7"],
}


def test_the_look_alike_letters_of_these_tests_are_cyrillic_or_greek():
    for latin, others in LOOK_ALIKES.items():
        for other in others:
            script = unicodedata.name(other).split()[0]
            assert script in ("CYRILLIC", "GREEK"), (latin, other)
            assert ("CAPITAL" in unicodedata.name(other)) == latin.isupper(), (latin, other)


@pytest.mark.parametrize(
    "name",
    [
        "\u04211 Ann",  # Cyrillic Es: reads "C1 Ann"
        "\u04051",  # Cyrillic Dze: reads "S1"
        "C-1 Ann",
        "C\u20131",  # en dash
        "C\u00b9 Ann",  # superscript one
        "\uff23\uff11",  # fullwidth C1
        "S1",
        "s 12",
        "Ann \u0441.3",
        "C\u2082",  # subscript two
        "CI Ann",  # capital i: reads "C1 Ann"
        "Cl Ann",  # small L
        "S|2",
    ],
)
def test_a_name_that_reads_like_a_seat_label_is_refused_with_a_sentence(name):
    assert looks_like_label(name)
    with pytest.raises(proto.ProtocolError) as err:
        proto.check_name(name)
    assert "looks like a player label" in str(err.value) and "pick a name" in str(err.value)
    assert "without C or S and a number" in str(err.value)  # (a user test: "Sam S2" was told "without C")


@pytest.mark.parametrize(
    "name", ["Ann", "C3PO", "Claire 2", "Scott", "Cs", "Class 5b", "\u03a9mega 2", "S\u00f8ren", "Sol", "Col", "Cliff"]
)
def test_names_that_only_contain_c_or_s_and_a_number_are_welcome(name):
    assert not looks_like_label(name)
    assert proto.check_name(name) == name


def test_a_second_ann_is_ann_2_and_a_third_ann_3():
    assert distinct_name("Ann", []) == "Ann"
    assert distinct_name("Ann", ["Ann"]) == "Ann 2"
    assert distinct_name("Ann", ["Ann", "Ann 2"]) == "Ann 3"
    assert distinct_name("ann", ["Ann"]) == "ann 2"  # case does not make a name distinct
    assert distinct_name("Bo", ["Ann"]) == "Bo"


def test_look_alike_names_get_a_number_and_the_numbers_themselves_stay_distinct():
    greek = "\u0391nn"  # Greek capital Alpha
    assert distinct_name(greek, ["Ann"]) == greek + " 2"
    assert distinct_name(greek, ["Ann", "Ann 2"]) == greek + " 3"  # "Αnn 2" would read as "Ann 2"
    assert distinct_name("Ann", [greek]) == "Ann 2"
    assert distinct_name("Ian", ["lan"]) == "Ian 2"  # capital I and small l
    assert distinct_name("Ann\u2014Lee", ["Ann-Lee"]) == "Ann\u2014Lee 2"  # em dash
    assert distinct_name("Ann  Lee", ["Ann Lee"]) == "Ann  Lee 2"
    assert distinct_name("B0b", ["Bob"]) == "B0b 2"  # a zero for an o
    assert distinct_name("Ann2", ["Ann", "Ann 2"]) == "Ann2 2"  # "Ann2" reads as "Ann 2"; "Ann22" does not
    assert distinct_name("Al1", ["All"]) == "Al1 2"


def test_a_numbered_name_fits_twenty_characters_and_never_reads_as_a_label():
    long = "Maximiliana Kowalska"  # 20
    assert distinct_name(long, [long]) == "Maximiliana Kowals 2"
    assert distinct_name("C", ["C"]) == "C (2)"  # "C 2" would read as the label C2
    assert not looks_like_label(distinct_name("S", ["s"]))


latin_names = st.text(alphabet=sorted(LOOK_ALIKES) + list("bdnrtuvw"), min_size=1, max_size=12)


@settings(max_examples=300, deadline=None)
@given(name=latin_names, data=st.data())
def test_any_look_alike_spelling_of_a_playing_name_is_made_distinct(name, data):
    positions = [i for i, ch in enumerate(name) if ch in LOOK_ALIKES]
    chosen = data.draw(st.sets(st.sampled_from(positions), min_size=1) if positions else st.just(set()))
    variant = "".join(data.draw(st.sampled_from(LOOK_ALIKES[ch])) if i in chosen else ch for i, ch in enumerate(name))
    shown = distinct_name(variant, [name])
    assert shown in (variant + " 2", variant + " (2)")  # "(2)" where "C 2" would read as a seat label
    # Back to Latin with this file's own table, the shown name is not the playing one.
    latin = {other: plain for plain, others in LOOK_ALIKES.items() for other in others}
    assert "".join(latin.get(ch, ch) for ch in shown) != name
    assert skeleton(variant) == skeleton(name)


def test_over_the_wire_a_second_ann_and_a_greek_ann_get_numbers_and_a_look_alike_label_is_refused(
    make_server,  # noqa: F811
    clients,  # noqa: F811
):
    server = make_server()
    assert clients(server.port).hello("Ann").label == "C1 Ann"
    second = clients(server.port).hello("Ann")
    assert (second.label, second.name) == ("C2 Ann 2", "Ann 2")
    assert clients(server.port).hello("\u0391nn").label == "C3 \u0391nn 3"
    assert server.player_names() == ["C1 Ann", "C2 Ann 2", "C3 \u0391nn 3"]
    impostor = clients(server.port)
    impostor.send(proto.encode_hello("\u04211 Ann"))
    assert "looks like a player label" in impostor.expect_error()
