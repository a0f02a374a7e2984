"""A diagnosis said in plain words and as data: the verdict, where the misfit is, its site, what to do next.

The CLI's text, its JSON and the model lab all say it from here, so they
say the same thing.
"""
from __future__ import annotations

from typing import Iterable

from analysis.diagnosis import acceptance, noise_floor, residuals
from analysis.diagnosis.candidates import Diagnosis
from analysis.diagnosis.sites import TIE_CHI2, SiteResult, tied_sites  # noqa: F401 (said from here too)
from analysis.effects import catalogue, registry
from analysis.effects.base import Effect, Site
from analysis.validity.findings import DRIFT
from analysis.fit.least_squares import FitResult

CHANNEL_SHORT = {"impedance": "Z", "displacement": "Hx"}
SITE_WORDS = {
    Site.BLOCKED: ("electrical", "ohms added to the blocked impedance Ze (the voice coil and what is in series "
                                 "with it)"),
    Site.FORCE_FACTOR: ("force-factor", "a factor on Bl, in the force and the back-EMF alike"),
    Site.MECHANICAL: ("mechanical", "kg/s added to the mechanical impedance Zm (losses, air load, a box, modes)"),
    Site.COMPLIANCE: ("compliance", "a factor on the suspension's compliance (how it yields with frequency)"),
    Site.CURRENT: ("current", "a factor on the measured current (the current sense)"),
    Site.DISPLACEMENT: ("displacement", "a factor on the measured displacement (the laser)"),
}
VERDICT_TITLES = {
    acceptance.NOTHING_MISSING: "Nothing missing",
    acceptance.EXPLAINED: "Explained",
    acceptance.PARTLY_EXPLAINED: "Partly explained",
    acceptance.UNEXPLAINED: "Unexplained",
}


def chi2_words(chi2_red: dict[str, float]) -> str:
    return ", ".join(f"{CHANNEL_SHORT.get(k, k)} {v:.3g}" for k, v in chi2_red.items())


def residual_json(fit: FitResult) -> list[dict]:
    """Where the residual sits, as data: the words of analysis.diagnosis.residuals.describe."""
    return [{"channel": f.channel, "f_lo": f.f_low, "f_hi": f.f_high, "kind": f.part, "sign": f.sign,
             "size_sigma": f.peak_sigma, "share": f.share} for f in residuals.findings(fit)]


def sites_json(sites: tuple[SiteResult, ...]) -> list[dict]:
    tied = {s.site for s in tied_sites(sites)}
    return [{**s.as_json(), "indistinguishable_from_best": s.site in tied} for s in sites]


def _site_sentence(fit: FitResult, sites: tuple[SiteResult, ...]) -> str:
    best = sites[0]
    if best.delta_bic >= -acceptance.MIN_BIC_GAIN:
        return ("No single site's smooth correction explains it either: the misfit is spread over several sites, "
                "or too sharp for a smooth correction (a narrow mode).")
    name, what = SITE_WORDS[best.site]
    text = (f"It belongs most likely at the {name} site: a smooth correction there ({what}) takes the reduced "
            f"χ² from {chi2_words(fit.chi2_red_by_channel())} to {chi2_words(best.chi2_red)}.")
    tied = [SITE_WORDS[s.site][0] for s in tied_sites(sites)]
    if "displacement" not in best.chi2_red:
        text += (" But with the impedance alone every site acts on Z only: the data cannot tell the sites apart "
                 "(a laser's Hx would).")
    elif tied:
        text += f" The data cannot tell it from the {' or the '.join(tied)} site."
    return text


def drift_from_validity(validity) -> str | None:
    """The validity check's drift findings (an analysis.validity.result.ResultValidity's, or None), in one sentence;
    None when there are none."""
    if validity is None:
        return None
    found = [f"{name}: {f.message}" for name, ch in validity.channels.items() for f in ch.findings
             if f.code == DRIFT]
    if validity.heating_words:
        found.append(validity.heating_words)
    return "; ".join(found) or None


def _next_step(sites: tuple[SiteResult, ...]) -> str:
    name, what = SITE_WORDS[sites[0].site]
    return (f"Next: write an effect of your own at the {name} site ({what}) that follows the correction's "
            f"shape (site = \"{sites[0].key}\" in an effect file, or the Model lab's New effect…), and fit it.")


def _flag_sentence(flags: Iterable[acceptance.Flag]) -> str:
    messages = [f.message for f in flags]
    return ("Flags: " + "; ".join(messages) + ".") if messages else ""


def first_site(result: Diagnosis) -> Site | None:
    """The site the verdict points the user at first: where the misfit left belongs when some is left (and a
    site's correction explains it), else the site of the first effect the path took; None when neither."""
    if result.verdict in (acceptance.PARTLY_EXPLAINED, acceptance.UNEXPLAINED) and result.sites \
            and result.sites[0].delta_bic < -acceptance.MIN_BIC_GAIN:
        return result.sites[0].site
    taken = next((step.chosen for step in result.steps if step.chosen is not None), None)
    return taken.effect.site if taken is not None else None


def own_effects_taken(result: Diagnosis) -> list[str]:
    """The ids of the user's own effects (not the catalogue's) that the path took."""
    taken = [step.chosen for step in result.steps if step.chosen is not None]
    effects: list[Effect] = [e for c in taken for e in (c.effect, c.partner) if e is not None]
    return [e.id for e in effects if e.id not in catalogue.IDS]


# Why the path stopped (stable codes: the JSON gives them).
STOP_NOISE_FLOOR = "noise-floor"
STOP_NONE_ACCEPTABLE = "none-acceptable"
STOP_STEP_CAP = "step-cap"
STOP_NOT_FOLLOWED = "not-followed"


def stop_reason(result: Diagnosis) -> tuple[str, str]:
    """Why the greedy path ended where it did: a code and a sentence."""
    last = result.steps[-1]
    if result.step_cap_reached:
        return STOP_STEP_CAP, (f"it reached its cap of {len(result.steps) - 1} steps; the last model was not "
                               "ranked further")
    if last.at_noise_floor:
        return STOP_NOISE_FLOOR, ("the model meets the noise on every channel, no site's smooth correction "
                                  "removes more than noise would and every parameter is determined: nothing is "
                                  "left to find")
    if last.chosen is not None:
        return STOP_NOT_FOLLOWED, f"the candidates were ranked, not followed (the best acceptable: {last.chosen.label})"
    ranked = [c for c in last.candidates if c.fit is not None]
    if not ranked:
        return STOP_NONE_ACCEPTABLE, "no candidate could be refitted"
    best = ranked[0]
    why = best.assessment.message if best.assessment is not None else "not assessed"
    return STOP_NONE_ACCEPTABLE, (f"none of the {len(last.candidates)} candidates passes the acceptance rule; the "
                                  f"best by delta BIC, {best.action} {best.label}, was not taken: {why}")


def verdict_headline(result: Diagnosis) -> str:
    """The verdict in one short sentence (verdict_text says it all)."""
    verdict = result.verdict
    moves = ", ".join(c.label for c in (step.chosen for step in result.steps) if c is not None)
    site = ""
    if result.sites and result.sites[0].delta_bic < -acceptance.MIN_BIC_GAIN:
        site = SITE_WORDS[result.sites[0].site][0]
    if verdict == acceptance.NOTHING_MISSING:
        text = "the model reaches the noise floor; nothing is missing."
    elif verdict == acceptance.EXPLAINED:
        text = f"{moves} brings the model to the noise floor."
    elif verdict == acceptance.PARTLY_EXPLAINED:
        text = f"{moves} helps; " + (f"the rest belongs at the {site} site." if site else "misfit is left.")
    else:
        text = "no effect of the catalogue explains the misfit" + (f"; look at the {site} site." if site else ".")
    if any(f.code == acceptance.NOISE_INFLATED for f in result.final_flags):
        text += " But χ² is far below 1: the noise estimate is inflated (drift?)."
    return text[:1].upper() + text[1:]


def verdict_text(result: Diagnosis, drift: str | None = None) -> str:
    """The verdict in plain words, with where the misfit is, its site and what to do next.

    `drift`: the validity check's drift finding, when the recording has one (said with an inflated noise).
    """
    verdict = result.verdict
    start, final = result.start, result.final
    taken = [step.chosen for step in result.steps if step.chosen is not None]
    moves = ", ".join(("replacing " + c.replaces.id + " by " if c.replaces else "adding ") + c.label
                      for c in taken)
    parts = []
    if verdict == acceptance.NOTHING_MISSING:
        parts.append(f"Nothing missing: the model explains the measurement down to its noise (reduced χ² "
                     f"{chi2_words(start.chi2_red_by_channel())}); no effect of the catalogue is needed.")
    elif verdict == acceptance.EXPLAINED:
        parts.append(f"Explained: {moves} brings the model to its noise floor (reduced χ² "
                     f"{chi2_words(start.chi2_red_by_channel())} → {chi2_words(final.chi2_red_by_channel())}).")
    elif verdict == acceptance.PARTLY_EXPLAINED:
        parts.append(f"Partly explained: {moves} helps (reduced χ² {chi2_words(start.chi2_red_by_channel())} → "
                     f"{chi2_words(final.chi2_red_by_channel())}), but misfit is left that no effect of the "
                     "catalogue" + (" or of your own" if registry.user_effects() else "") + " explains.")
    else:
        parts.append(f"Unexplained: no effect of the catalogue explains the misfit (reduced χ² "
                     f"{chi2_words(start.chi2_red_by_channel())}); none was added.")
    own = own_effects_taken(result)
    if own and verdict == acceptance.EXPLAINED:
        parts.append(f"{' and '.join(own)} {'is an effect' if len(own) == 1 else 'are effects'} of your own: "
                     "it explained what the catalogue's effects did not.")
    if result.steps[-1].at_noise_floor:
        parts.append(noise_floor.SKIPPED_WORDS if not taken else noise_floor.ENDED_WORDS)
    if verdict in (acceptance.PARTLY_EXPLAINED, acceptance.UNEXPLAINED):
        parts.append(f"Where: {residuals.describe(final)}.")
        if result.sites:
            parts.append(_site_sentence(final, result.sites))
            if result.sites[0].delta_bic < -acceptance.MIN_BIC_GAIN:
                parts.append(_next_step(result.sites))
    if result.step_cap_reached:
        parts.append(f"The path stopped at its cap of {len(result.steps) - 1} steps: diagnose again from the "
                     "last model to go on.")
    inflated = [f for f in result.final_flags if f.code == acceptance.NOISE_INFLATED]
    if inflated:
        parts.append("But the reduced χ² is far below 1 (" + ", ".join(
            f"{CHANNEL_SHORT.get(f.channel, f.channel)} {final.channels[f.channel].chi2_red:.2g}" for f in inflated)
            + "): the noise estimate is inflated, not met. The scatter between periods is larger than what the "
              "model leaves, as when the driver drifts during the measurement (a voice coil warming up): see "
              "the drift finding of the validity check." + (f" It reports: {drift}" if drift else ""))
    elif drift and "voice coil warmed" in drift:
        parts.append("During the measurement " + drift[drift.index("the voice coil warmed"):] + ".")
    others = [f for f in result.final_flags if f.code not in (acceptance.NOISE_INFLATED, acceptance.STEP_CAP)]
    flags = _flag_sentence(others)
    if flags:
        parts.append(flags)
    return " ".join(parts)
