"""The material a particle case runs: the material file with the case's own `material` table
laid over it, key by key (cases.toml: `material = { grains = { diameter_m = 0.0035 } }` runs a
scene with other grains). The run (run_dem.py) and the stored reference's reader
(reference_file.py) both take it from here."""


def material_of(case, material):
    """MATERIAL (a parsed material.toml) with CASE's `material` table over it. Raises ValueError
    naming a key the material file does not have."""
    def merged(base, over, where):
        out = dict(base)
        for k, v in over.items():
            if k not in base:
                raise ValueError(f"material.{where}{k}: not a key of the material file")
            out[k] = merged(base[k], v, f"{where}{k}.") if isinstance(v, dict) else v
        return out
    return merged(material, case.get("material", {}), "")
