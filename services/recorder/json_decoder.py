"""An mcap :class:`~mcap.decoder.DecoderFactory` for JSON channels (``json`` encoding).

mcap's Python package decodes no JSON by itself; this is the whole of it::

    reader = make_reader(handle, decoder_factories=[JsonDecoderFactory()])
    for schema, channel, message, data in reader.iter_decoded_messages():
        ...  # data is the message's JSON object as a dict
"""

from __future__ import annotations

import json
from collections.abc import Callable
from typing import Any

from mcap.decoder import DecoderFactory
from mcap.records import Schema
from mcap.well_known import MessageEncoding


class JsonDecoderFactory(DecoderFactory):
    """Decodes messages of channels whose message encoding is ``json``."""

    def decoder_for(
        self, message_encoding: str, schema: Schema | None
    ) -> Callable[[bytes], Any] | None:
        if message_encoding != MessageEncoding.JSON:
            return None
        return json.loads
