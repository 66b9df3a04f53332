#!/usr/bin/env python3
"""Rewrite each `NAME = erode:stream-power(...)` statement of a spec as `NAME = erode:evolve(...) { ... }`,
the same model as a body of process plugins (docs/processes.md), which gives the same bytes.

    python3 tools/to_processes.py pipelines/rif.orogen            # prints the rewritten spec
    python3 tools/to_processes.py -i pipelines/rif.orogen         # rewrites it in place

glaciers=true becomes glaciers() before the incision and troughs() after the floodplains; chi=true becomes
chi(concavity=m/n) last."""
import re
import sys

NODE = {"years", "dt", "substeps", "open", "base_level", "timelapse_every"}
PROCESSES = [  # (process, {node parameter: process parameter}), in erode:stream-power's order
    ("uplift", {"uplift": "rate", "uplift_layer": "layer", "uplift_layer_years": "layer_years",
                "uplift_smoothing": "smoothing", "uplift_edge_taper": "edge_taper",
                "uplift_history_years": "history_years"}),
    ("rain", {"rain_background": "background", "wind_from": "wind_from", "wind_speed": "wind_speed",
              "wind_share": "wind_share", "condensation_time": "condensation_time", "fallout_time": "fallout_time",
              "moist_stability": "moist_stability", "vapour_scale_height": "vapour_scale_height",
              "uplift_sensitivity": "uplift_sensitivity", "rain_resolution": "resolution"}),
    ("flow", {"routing": "routing", "mfd_exponent": "mfd_exponent", "depressions": "depressions"}),
    ("creep", {"diffusivity": "diffusivity"}),
    ("rock", {"landslide_angle": "angle", "bed_angle_spread": "angle_spread", "landslide_block_spread": "block_spread",
              "bed_thickness": "thickness", "bed_dip": "dip", "bed_dip_toward": "dip_toward",
              "bed_erodibility_contrast": "erodibility_contrast", "bed_fold_amplitude": "fold_amplitude",
              "bed_fold_wavelength": "fold_wavelength", "bed_thickness_spread": "thickness_spread",
              "bed_fault_spacing": "fault_spacing", "bed_fault_throw": "fault_throw",
              "bed_facies_length": "facies_length", "bed_facies_share": "facies_share"}),
    ("glaciers", {"ela": "ela", "ice_balance_gradient": "balance_gradient", "ice_max_balance": "max_balance",
                  "ice_erodibility": "erodibility", "ice_flux_exponent": "flux_exponent",
                  "glacier_min_flux": "min_flux"}),
    ("stream-power", {"erodibility": "erodibility", "m": "m", "n": "n", "channel_area": "channel_area",
                      "deposition": "deposition"}),
    ("banks", {"bank_erosion": "erosion", "bank_area": "area", "bank_floor_slope": "floor_slope",
               "bank_wide_area": "wide_area", "bank_wider_area": "wider_area", "bank_widest_floor": "widest_floor"}),
    ("floodplains", {"floodplain_area": "area", "floodplain_width": "width", "floodplain_exponent": "exponent",
                     "floodplain_slope": "slope", "floodplain_max_slope": "max_slope"}),
    ("troughs", {"glacier_half_width": "half_width", "trough_wall_angle": "wall_angle",
                 "glacier_min_flux": "min_flux"}),
    ("landslides", {"landslide_angle": "angle"}),
    ("chi", {}),
]


def split_args(text):
    """The call's arguments, split at the commas outside brackets and quotes."""
    args, depth, quote, cur = [], 0, False, ""
    for c in text:
        if c == '"':
            quote = not quote
        elif not quote and c in "([":
            depth += 1
        elif not quote and c in ")]":
            depth -= 1
        if c == "," and depth == 0 and not quote:
            args.append(cur.strip())
            cur = ""
        else:
            cur += c
    if cur.strip():
        args.append(cur.strip())
    return args


def number(value):
    try:
        return float(value)
    except ValueError:
        return None


def call_lines(head, params, indent, width=120):
    """head(k=v, ...) wrapped at `width` columns, continuation lines under the first parameter."""
    lines, cur = [], indent + head + "("
    pad = " " * len(cur)
    for k, (key, value) in enumerate(params):
        item = f"{key}={value}" + (", " if k + 1 < len(params) else ")")
        if len(cur) + len(item.rstrip()) > width and not cur.endswith("("):
            lines.append(cur.rstrip())
            cur = pad
        cur += item
    if not params:
        cur += ")"
    lines.append(cur)
    return lines


def rewrite(name, inputs, params, comment):
    given = dict(params)
    node = [(k, v) for k, v in params if k in NODE]
    body = []
    for process, names in PROCESSES:
        mine = [(names[k], v) for k, v in params if k in names]
        if process == "rain" and given.get("rain", "uniform").strip('"') != "orographic":
            continue
        if process == "rock":
            mine = [(k, v) for k, v in mine if k != "angle" or any(p.startswith("bed_") or p == "landslide_block_spread"
                                                                   for p in given)]
            if not any(p.startswith("bed_") or p == "landslide_block_spread" for p in given):
                continue
        if process == "banks" and not (number(given.get("bank_erosion", "0")) or 0) > 0:
            continue
        if process == "floodplains" and not (number(given.get("floodplain_area", "0")) or 0) > 0:
            continue
        if process == "landslides" and not (number(given.get("landslide_angle", "0")) or 0) > 0:
            continue
        if process in ("glaciers", "troughs") and given.get("glaciers") != "true":
            continue
        if process == "chi":
            if given.get("chi") != "true":
                continue
            mine = [("concavity", repr(float(given.get("m", "0.45")) / float(given.get("n", "1"))))]
        if process == "creep" and "diffusivity" not in given:
            mine = [("diffusivity", "0.01")]  # erode:stream-power's default
        body.append((process, mine))
    head = f"{name} = erode:evolve(" if False else f"{name:<6} = erode:evolve("
    first = head + ", ".join(inputs + [f"{k}={v}" for k, v in node]) + ") {" + (f"  {comment}" if comment else "")
    out = [first]
    for process, mine in body:
        out += call_lines(process, mine, "    ")
    out.append("}")
    return "\n".join(out)


def convert(text):
    pattern = re.compile(r"^(\w+)\s*=\s*erode:stream-power\(", re.M)
    pos, result = 0, ""
    for m in pattern.finditer(text):
        if m.start() < pos:
            continue
        depth, i = 1, m.end()
        while depth:
            depth += {"(": 1, ")": -1}.get(text[i], 0)
            i += 1
        end = text.find("\n", i)
        end = len(text) if end < 0 else end
        comment = text[i:end].strip()
        args = split_args(re.sub(r"\s*\n\s*", " ", text[m.end():i - 1]))
        inputs = [a for a in args if "=" not in a]
        params = [tuple(p.strip() for p in a.split("=", 1)) for a in args if "=" in a]
        new = rewrite(m.group(1), inputs, params, comment)
        if new is None:
            continue
        result += text[pos:m.start()] + new
        pos = end
    return result + text[pos:]


if __name__ == "__main__":
    in_place = "-i" in sys.argv
    for path in [a for a in sys.argv[1:] if a != "-i"]:
        text = convert(open(path).read())
        if in_place:
            open(path, "w").write(text)
        else:
            sys.stdout.write(text)
