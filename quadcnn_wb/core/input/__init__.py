"""Input stage: exact boundary curves, validated into a Domain (JSON or CAD), its pose."""
