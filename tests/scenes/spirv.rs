//! An effect no material uses is absent from the compiled kernel, checked on the SPIR-V: spirv-opt sets the
//! plan's specialisation constants, freezes and folds them and removes dead branches, functions and code
//! (src/scene/spirv.rs); the effect's functions must then be gone, and switching the effect on must bring them
//! back and add instructions. Light types work the same way through their counts.

use crate::common;
use brdfprof::kernels;
use brdfprof::model::KernelKind;
use brdfprof::scene::Scene;
use brdfprof::scene::gbuffer;
use brdfprof::scene::plan::{self, Effect};
use brdfprof::scene::spirv;

/// Functions that only an effect uses.
fn functions_of(effect: Effect) -> &'static [&'static str] {
    match effect {
        Effect::Anisotropy => &["specular_anisotropic", "D_GgxAnisotropic", "Vis_SmithGgxCorrelatedAnisotropic"],
        Effect::EnergyCompensation => &["surface_energy", "e_lookup", "energy_compensation"],
        Effect::Diffuse => &["diffuse_lobe", "Fd_Lambert", "Fd_Burley"],
        Effect::ClearCoat => &["clear_coat_lobe", "clear_coat_fresnel"],
    }
}

#[test]
fn effects_no_material_uses_are_absent_from_the_kernel() {
    let scene = Scene::load(&common::repo_root().join("scenes/sphere-grid.json")).unwrap();
    let mut file = scene.file.clone();
    file.gbuffer = match file.gbuffer {
        brdfprof::scene::format::GBufferSource::Procedural(brdfprof::scene::format::Procedural::SphereGrid {
            rows,
            columns,
            floor,
            ..
        }) => brdfprof::scene::format::GBufferSource::Procedural(brdfprof::scene::format::Procedural::SphereGrid {
            size: brdfprof::scene::format::Size([64, 28]),
            rows,
            columns,
            floor,
        }),
        _ => panic!("sphere-grid.json is a sphere grid"),
    };
    let scene = Scene { file, ..scene };
    let g = gbuffer::build(&scene).unwrap();
    let p = plan::plan(&scene, &g, None);
    assert_eq!(p.kernels.len(), 1);
    let switches = p.kernels[0].switches;
    let kernel = p.kernels[0].model.kernel(KernelKind::Scene, kernels::embedded()).unwrap();
    let (source, model_constants) = (&kernel.spirv, kernel.constants);
    let as_planned = spirv::specialise(source, &p.constants(model_constants.clone(), switches)).unwrap();
    println!(
        "as planned ({switches:?}): {} instructions, functions {:?}",
        as_planned.instructions, as_planned.functions
    );
    for effect in Effect::ALL {
        let names = functions_of(effect);
        if effect.is_on(&switches) {
            continue;
        }
        for f in names {
            assert!(
                !as_planned.functions.iter().any(|x| x == f),
                "{} is off in the scene, but {f} is in the kernel",
                effect.name()
            );
        }
        // Switched on, the same kernel carries the effect: the check above can fail.
        let mut on = switches;
        match effect {
            Effect::Anisotropy => on.anisotropy = true,
            Effect::EnergyCompensation => on.energy = 1,
            Effect::Diffuse => on.diffuse = 2,
            Effect::ClearCoat => on.clear_coat = true,
        }
        let with = spirv::specialise(source, &p.constants(model_constants.clone(), on)).unwrap();
        println!(
            "{} on: {} instructions (+{})",
            effect.name(),
            with.instructions,
            with.instructions as i64 - as_planned.instructions as i64
        );
        assert!(
            names.iter().any(|f| with.functions.iter().any(|x| x == f)),
            "{} on, but none of {names:?} in the kernel",
            effect.name()
        );
        assert!(with.instructions > as_planned.instructions, "{} adds no instructions", effect.name());
    }
    // The scene's diffuse lobe is on (Lambert on some materials, none on the metal: chosen per pixel).
    assert_eq!(switches.diffuse, 3);
    let off = spirv::specialise(source, &p.constants(model_constants.clone(), Effect::Diffuse.off(switches))).unwrap();
    assert!(
        !off.functions.iter().any(|x| x == "diffuse_lobe") && as_planned.functions.iter().any(|x| x == "diffuse_lobe")
    );
    assert!(off.instructions < as_planned.instructions);
    // Light types: the scene has no spot or sphere light; one of each adds instructions.
    assert_eq!((p.counts.spot, p.counts.sphere), (0, 0));
    let mut more = p.clone();
    more.counts.spot = 1;
    let spot = spirv::specialise(source, &more.constants(model_constants, switches)).unwrap();
    assert!(
        spot.instructions > as_planned.instructions,
        "a spot light adds nothing: {} vs {}",
        spot.instructions,
        as_planned.instructions
    );
}
