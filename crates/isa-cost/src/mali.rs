//! The Bifrost/Valhall compiler's statistics (Mesa's Panfrost compiler, `BIFROST_MESA_DEBUG=shaderdb`): its
//! `SHADER-DB:` line read as statistics, and its per-pipe cycles per thread as a bound (`bi_print_stats` in
//! src/panfrost/bifrost/bifrost_compile.c for Bifrost, `va_print_stats` for Valhall).

use crate::schedule::Schedule;
use crate::{Stat, driver_stat};
use anyhow::{Result, anyhow, bail};

/// The prefix of the compiler's statistics lines (`fprintf(stderr, "SHADER-DB: %s\n", ...)`).
const LINE_PREFIX: &str = "SHADER-DB: ";

/// The fields of the compiler's statistics line (Bifrost's `bi_print_stats`, Valhall's `va_print_stats`: its
/// word after each number) and the statistic names brdfprof gives them.
const FIELDS: [(&str, &str); 18] = [
    ("inst", "Instructions"),
    ("tuples", "Tuples"),
    ("clauses", "Clauses"),
    ("cycles", "Bound cycles"),
    ("arith", "Arithmetic cycles"),
    ("texture", "Texture cycles"),
    ("vary", "Varying cycles"),
    ("ldst", "Load-store cycles"),
    ("fma", "FMA cycles"),
    ("cvt", "CVT cycles"),
    ("sfu", "SFU cycles"),
    ("v", "Varying cycles"),
    ("t", "Texture cycles"),
    ("ls", "Load-store cycles"),
    ("quadwords", "Quadwords"),
    ("threads", "Threads"),
    ("preloads", "Preloads"),
    ("loops", "Loops"),
];

/// The per-pipe cycles and the pipe each names (Bifrost's arithmetic pipe is Valhall's FMA, CVT and SFU).
const PIPES: [(&str, &str); 7] = [
    ("Arithmetic cycles", "arithmetic"),
    ("FMA cycles", "FMA"),
    ("CVT cycles", "CVT"),
    ("SFU cycles", "SFU"),
    ("Texture cycles", "texture"),
    ("Varying cycles", "varying"),
    ("Load-store cycles", "load/store"),
];

/// The statistics shown beside cycles/eval (the busiest pipe, the compiler's "Bound cycles", is the rule's own
/// column).

/// One pipeline's stderr: its compute shader's `SHADER-DB:` line as statistics, the other lines passed on.
pub fn read_shaderdb(log: &str) -> Result<(Vec<Stat>, Vec<String>)> {
    let (lines, rest): (Vec<&str>, Vec<&str>) = log.lines().partition(|l| l.starts_with(LINE_PREFIX));
    let compute: Vec<&str> =
        lines.iter().filter_map(|l| l[LINE_PREFIX.len()..].strip_prefix("MESA_SHADER_COMPUTE shader: ")).collect();
    let line = match compute.as_slice() {
        [one] => *one,
        [] => bail!(
            "the Bifrost compiler printed no `SHADER-DB: MESA_SHADER_COMPUTE` line (is BIFROST_MESA_DEBUG=shaderdb reaching the driver?)"
        ),
        many => bail!("the Bifrost compiler printed {} compute-shader statistics lines for one pipeline", many.len()),
    };
    let mut stats = Vec::new();
    let mut stat = |name: &str, value: f64| {
        stats.push(Stat {
            name: name.into(),
            description: format!("Bifrost compiler (bi_print_stats; va_print_stats for Valhall): {name}"),
            value,
        })
    };
    for field in line.split(", ") {
        let (number, word) =
            field.trim().split_once(' ').ok_or_else(|| anyhow!("unreadable field `{field}` in `{line}`"))?;
        if word == "spills:fills" {
            let (spills, fills) =
                number.split_once(':').ok_or_else(|| anyhow!("unreadable spills:fills `{number}` in `{line}`"))?;
            stat("Spills", spills.parse()?);
            stat("Fills", fills.parse()?);
            continue;
        }
        let name = FIELDS
            .iter()
            .find(|(w, _)| *w == word)
            .map(|(_, n)| *n)
            .ok_or_else(|| anyhow!("unknown field `{word}` in `{line}`"))?;
        stat(name, number.parse().map_err(|e| anyhow!("`{number}` in `{line}`: {e}"))?);
    }
    Ok((stats, rest.into_iter().map(str::to_string).collect()))
}

type Stats = std::collections::BTreeMap<String, f64>;

/// Whether the compiler kept the light loop (which shade.glsl asks to be unrolled and Bifrost keeps rolled): it
/// counts a loop's body once, so one pass through the program is then one light's evaluation. A BRDF's own kept
/// loops come `lights` times over (shade.glsl writes the block out for a file with a loop of unknown trip count),
/// a kept light loop once with its body's: a loop count that is not a multiple of the lights. (Read wrongly
/// where a kept light loop holds lights - 1 kept loops of a BRDF whose trip counts are literals.)
pub fn rolled(stats: &Stats, lights: u32) -> bool {
    let loops = driver_stat(stats, "Loops").unwrap_or(0.0);
    loops > 0.0 && (lights <= 1 || loops % f64::from(lights) != 0.0)
}

/// The per-pipe cycles the compiler reported for a kernel (its architecture's).
pub fn pipes(stats: &Stats) -> Option<Vec<(String, f64)>> {
    let pipes: Vec<(String, f64)> =
        PIPES.iter().filter_map(|(stat, pipe)| driver_stat(stats, stat).map(|v| (pipe.to_string(), v))).collect();
    (!pipes.is_empty()).then_some(pipes)
}

/// A kernel's pipes as a bound with no latency term, and the evaluations they stand for. An unrolled program
/// holds every light's evaluation (/ lights). A rolled one counts one light's body and, once, the per-pixel
/// loads and store outside the loop: the per-pixel part is `per_pixel` (the memory-only kernel's own figures,
/// where it kept its loop too: its body does no BRDF work), charged 1 / lights per evaluation, the rest whole.
pub fn pipes_of(stats: &Stats, lights: u32, per_pixel: Option<&[(String, f64)]>) -> Option<(Schedule, f64)> {
    let mut pipes = pipes(stats)?;
    if !rolled(stats, lights) {
        return Some((Schedule { pipes, latency: None, resident_waves: None }, f64::from(lights)));
    }
    if let Some(per_pixel) = per_pixel {
        let shared = 1.0 - 1.0 / f64::from(lights.max(1));
        for (name, v) in &mut pipes {
            let p = per_pixel.iter().find(|(n, _)| n == name).map_or(0.0, |(_, x)| *x);
            *v = (*v - p * shared).max(0.0);
        }
    }
    Some((Schedule { pipes, latency: None, resident_waves: None }, 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    const GGX: &str = "SHADER-DB: MESA_SHADER_COMPUTE shader: 174 inst, 145 tuples, 23 clauses, 8.000000 cycles, 5.750000 arith, 0.000000 texture, 0.000000 vary, 8.000000 ldst, 121 quadwords, 2 threads, 3 preloads, 0 loops, 1:2 spills:fills";

    #[test]
    fn a_loop_count_that_is_a_multiple_of_the_lights_is_the_brdfs_not_the_light_loop() {
        let stats = |loops: f64| Stats::from([("driver/Compute Shader/Loops".to_string(), loops)]);
        assert!(!rolled(&stats(0.0), 8));
        assert!(rolled(&stats(1.0), 8), "the light loop kept");
        assert!(rolled(&stats(2.0), 8), "the light loop kept around one loop of the BRDF's");
        assert!(!rolled(&stats(8.0), 8), "the block written out, the BRDF's loop in each light");
        assert!(!rolled(&stats(16.0), 8));
    }

    #[test]
    fn reads_the_compute_line_and_passes_the_rest_on() {
        let (stats, rest) = read_shaderdb(&format!("drm-shim: hello\n{GGX}\n")).unwrap();
        let get = |n: &str| stats.iter().find(|s| s.name == n).map(|s| s.value);
        assert_eq!(
            (get("Instructions"), get("Arithmetic cycles"), get("Load-store cycles"), get("Bound cycles")),
            (Some(174.0), Some(5.75), Some(8.0), Some(8.0))
        );
        assert_eq!((get("Spills"), get("Fills"), get("Preloads")), (Some(1.0), Some(2.0), Some(3.0)));
        assert_eq!(rest, vec!["drm-shim: hello".to_string()]);
        assert!(read_shaderdb("nothing here").unwrap_err().to_string().contains("no `SHADER-DB"));
        assert!(read_shaderdb(&format!("{GGX}\n{GGX}")).unwrap_err().to_string().contains("2 compute-shader"));
        assert!(
            read_shaderdb(&GGX.replace("tuples", "tupels")).unwrap_err().to_string().contains("unknown field `tupels`")
        );
    }
}
