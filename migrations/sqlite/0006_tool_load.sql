-- robocal schema, version 6: a tool's load (issue 31).
--
-- The load a production tool carries, as the API takes it:
-- {"mass_kg": .., "com_mm": [..], "frame": "flange"|"tool", "inertia_kgm2": [..]}
-- (core::cell::load); NULL for work objects and for tools without a stated
-- load (a solve then keeps the model's payload at its flange point).
ALTER TABLE cell_items ADD COLUMN load_json TEXT;
