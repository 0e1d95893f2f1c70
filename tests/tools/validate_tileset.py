#!/usr/bin/env python3
"""Validates 3D Tiles tileset JSON files against the 3D Tiles 1.1 JSON schema.

    python3 tests/tools/validate_tileset.py OUTDIR/tileset.json ...

The schema is the specification's own (JSON Schema 2020-12, CesiumGS/3d-tiles
specification/schema, the files tileset.schema.json refers to, in tests/data/3d-tiles-schema with
their source and licence), read by Debian's python3-jsonschema; no network is used. Beyond the
schema, every content URI must name a file beside the tileset. Prints one line per problem and
exits 0 when every tileset is valid, 1 when one is not, 2 when a file cannot be read or the
validator cannot run.
"""
import json
import pathlib
import sys
import warnings

SCHEMA_DIR = pathlib.Path(__file__).resolve().parents[1] / "data" / "3d-tiles-schema"


def load_validator():
    """A Draft 2020-12 validator of tileset.schema.json whose $refs resolve inside SCHEMA_DIR only."""
    import jsonschema

    warnings.filterwarnings("ignore", message="jsonschema", category=DeprecationWarning)
    store, by_name = {}, {}
    for path in sorted(SCHEMA_DIR.rglob("*.schema.json")):
        schema = json.loads(path.read_text())
        jsonschema.Draft202012Validator.check_schema(schema)
        store[path.as_uri()] = schema
        by_name[path.name] = schema  # the names are unique across the folders
    root = SCHEMA_DIR / "tileset.schema.json"
    schema = store[root.as_uri()]

    class LocalResolver(jsonschema.RefResolver):
        def resolve_remote(self, uri):
            # By name when a newer jsonschema (4.18+, RefResolver deprecated) joined a $ref to the
            # scope of a schema it left; Debian 12's 4.10 resolves every one by its full URI.
            name = uri.rsplit("/", 1)[-1]
            if uri not in store and name not in by_name:
                raise jsonschema.RefResolutionError("%s: not in %s" % (uri, SCHEMA_DIR))
            return store.get(uri, by_name.get(name))

    resolver = LocalResolver(base_uri=root.as_uri(), referrer=schema, store=store)
    return jsonschema.Draft202012Validator(schema, resolver=resolver)


def problems(validator, path):
    """Every problem of one tileset, as text lines."""
    tileset = json.loads(pathlib.Path(path).read_text())
    out = []
    for error in sorted(validator.iter_errors(tileset), key=lambda e: list(e.absolute_path)):
        where = "/".join(str(p) for p in error.absolute_path) or "(top)"
        out.append("%s: %s: %s" % (path, where, error.message))

    def walk(tile, where):
        if not isinstance(tile, dict):
            return
        uri = tile.get("content", {}).get("uri") if isinstance(tile.get("content"), dict) else None
        if isinstance(uri, str) and not (pathlib.Path(path).parent / uri).is_file():
            out.append("%s: %s/content/uri: %s is not a file beside the tileset" % (path, where, uri))
        for k, child in enumerate(tile.get("children", []) if isinstance(tile.get("children"), list) else []):
            walk(child, "%s/children/%d" % (where, k))

    walk(tileset.get("root"), "root")
    return out


def main(argv):
    if not argv:
        print("usage: python3 tests/tools/validate_tileset.py TILESET.json...", file=sys.stderr)
        return 2
    try:
        validator = load_validator()
    except ImportError:
        print("validate_tileset: python3-jsonschema is missing (apt-get install python3-jsonschema)", file=sys.stderr)
        return 2
    failed = False
    for path in argv:
        try:
            lines = problems(validator, path)
        except (OSError, ValueError) as e:
            print("validate_tileset: %s: %s" % (path, e), file=sys.stderr)
            return 2
        for line in lines:
            print(line)
        failed = failed or bool(lines)
        print("%s: %s" % (path, "%d problems" % len(lines) if lines else "valid 3D Tiles 1.1"))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
