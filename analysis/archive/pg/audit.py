"""The audit trail the server enforces (schema versions 3 and 4): who stored what and when is the server's word.

Version 1 gave each role INSERT on whole tables, with `stored_by`,
`received_at`, `created_by` as column defaults a client could override: an
operator could store a measurement under another user's name and any date,
one station add a parameter to another station's measurement, an engineer
back-date a limits version under another name, and a limits document linpar
cannot read stopped `qa stats` for everyone. Here, whatever program connects:

- BEFORE INSERT triggers set stored_by/received_at, created_by/created_at and
  added_by/added_at from the session (session_user, now());
- a parameter is added only to a measurement its session user stored;
- a limits version must be a linpar-limits/1 document (linpar.limits_document_ok,
  a CHECK), its name one line of text; the measurements' names too (the
  class analysis.text_boundary refuses). The CHECKs are NOT VALID: rows stored
  before stay readable (a reader flags what breaks the rule), new ones are checked.

Version 4 adds the bidirectional controls to the class the server refuses in
those names, as analysis.text_boundary does: "st2" + U+202E + "SSAP" read
"st2PASS" beside a verdict, and a program other than linpar could store it.
"""
from __future__ import annotations

from analysis.text_boundary import BIDI_CLASS

# The characters analysis.text_boundary.CONTROL refuses, as a PostgreSQL regular expression (ARE escapes).
_CONTROL_RE = r"'[\x01-\x1f\x7f-\x9f\u2028\u2029]'"

V3_AUDIT = rf"""
CREATE FUNCTION linpar.stamp_measurement() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    NEW.stored_by := session_user;
    NEW.received_at := now();
    RETURN NEW;
END $$;
CREATE TRIGGER stamp BEFORE INSERT ON linpar.measurements
    FOR EACH ROW EXECUTE FUNCTION linpar.stamp_measurement();

CREATE FUNCTION linpar.stamp_limits_version() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    NEW.created_by := session_user;
    NEW.created_at := now();
    RETURN NEW;
END $$;
CREATE TRIGGER stamp BEFORE INSERT ON linpar.limits_versions
    FOR EACH ROW EXECUTE FUNCTION linpar.stamp_limits_version();

CREATE FUNCTION linpar.stamp_golden_unit() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    NEW.added_by := session_user;
    NEW.added_at := now();
    RETURN NEW;
END $$;
CREATE TRIGGER stamp BEFORE INSERT ON linpar.golden_units
    FOR EACH ROW EXECUTE FUNCTION linpar.stamp_golden_unit();

CREATE FUNCTION linpar.own_measurement() RETURNS trigger LANGUAGE plpgsql AS $$
BEGIN
    IF NOT EXISTS (SELECT 1 FROM linpar.measurements WHERE id = NEW.measurement_id
                   AND stored_by = session_user) THEN
        RAISE EXCEPTION 'measurement % was not stored by %', NEW.measurement_id, session_user
            USING ERRCODE = 'insufficient_privilege';
    END IF;
    RETURN NEW;
END $$;
CREATE TRIGGER own BEFORE INSERT ON linpar.parameters
    FOR EACH ROW EXECUTE FUNCTION linpar.own_measurement();

CREATE FUNCTION linpar.limits_document_ok(doc jsonb, doc_name text) RETURNS boolean
LANGUAGE plpgsql IMMUTABLE AS $$
DECLARE
    entry record;
BEGIN
    IF jsonb_typeof(doc) IS DISTINCT FROM 'object' OR doc->>'format' IS DISTINCT FROM 'linpar-limits/1'
       OR doc_name ~ {_CONTROL_RE}
       OR (doc ? 'name' AND jsonb_typeof(doc->'name') NOT IN ('string', 'null'))
       OR jsonb_typeof(doc->'parameters') IS DISTINCT FROM 'object' OR doc->'parameters' = '{{}}'::jsonb THEN
        RETURN false;
    END IF;
    FOR entry IN SELECT key, value FROM jsonb_each(doc->'parameters') LOOP
        IF jsonb_typeof(entry.value) <> 'object' OR jsonb_typeof(entry.value->'unit') IS DISTINCT FROM 'string'
           OR EXISTS (SELECT 1 FROM jsonb_object_keys(entry.value) k
                      WHERE k NOT IN ('nominal', 'tolerance', 'min', 'max', 'unit', 'note'))
           OR EXISTS (SELECT 1 FROM unnest(ARRAY['nominal', 'min', 'max']) k
                      WHERE entry.value ? k AND jsonb_typeof(entry.value->k) <> 'number')
           OR (entry.value ? 'tolerance' AND jsonb_typeof(entry.value->'tolerance') NOT IN ('number', 'string'))
           OR NOT (entry.value ? 'nominal' AND entry.value ? 'tolerance' OR entry.value ? 'min'
                   OR entry.value ? 'max')
           OR (entry.value ? 'min' AND entry.value ? 'max'
               AND (entry.value->>'min')::double precision > (entry.value->>'max')::double precision) THEN
            RETURN false;
        END IF;
    END LOOP;
    RETURN true;
END $$;
ALTER TABLE linpar.limits_versions ADD CONSTRAINT limits_document_checked
    CHECK (linpar.limits_document_ok(document, name)) NOT VALID;
ALTER TABLE linpar.measurements ADD CONSTRAINT names_one_line
    CHECK (driver !~ {_CONTROL_RE} AND serial !~ {_CONTROL_RE} AND operator !~ {_CONTROL_RE}
           AND station !~ {_CONTROL_RE}) NOT VALID;
"""

# The bidirectional controls, as a PostgreSQL regular expression (ARE escapes, as _CONTROL_RE).
_BIDI_RE = f"'[{BIDI_CLASS}]'"

V4_BIDI = f"""
ALTER TABLE linpar.measurements ADD CONSTRAINT names_without_bidi_controls
    CHECK (driver !~ {_BIDI_RE} AND serial !~ {_BIDI_RE} AND operator !~ {_BIDI_RE}
           AND station !~ {_BIDI_RE}) NOT VALID;
ALTER TABLE linpar.limits_versions ADD CONSTRAINT name_without_bidi_controls
    CHECK (name !~ {_BIDI_RE}) NOT VALID;
"""

# Set by `linpar archive setup` on the database (ALTER DATABASE ... SET), for every session: a station whose
# link is cut in the middle of a transaction holds its locks until the server notices; these bound that.
SERVER_SETTINGS = {"idle_in_transaction_session_timeout": "60s", "tcp_keepalives_idle": "10",
                   "tcp_keepalives_interval": "5", "tcp_keepalives_count": "3"}
# Set by every station on its own sessions (libpq's options): a store that waits on a lock gives up in
# seconds and goes to the local queue instead of hanging (analysis.archive.pg.server).
STATION_OPTIONS = "-c lock_timeout=5s -c statement_timeout=120s -c idle_in_transaction_session_timeout=60s"
