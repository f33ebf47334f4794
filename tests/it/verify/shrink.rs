//! Shrinks a failing scene for a reader: `VERIFY_SEED=S cargo test --test it verify_shrink
//! -- --ignored --nocapture` removes nodes one at a time (lights, shapes, whole groups) for as
//! long as `exact` still fails on the scene, and writes what is left to
//! `target/verify-failures/seed-S-shrunk.wrl` with the failures it still shows.

use super::scenes::{Node, SceneDesc};
use super::{checks, failures_dir, reference_parallel, viewer_carried, world::World};
use gtsphere::render::Integrator;

/// Nodes in pre-order (groups and what they hold).
fn count(nodes: &[Node]) -> usize {
    nodes
        .iter()
        .map(|n| match n {
            Node::Group { children, .. } => 1 + count(children),
            _ => 1,
        })
        .sum()
}

/// `nodes` without the node of pre-order index `k`.
fn without(nodes: &[Node], k: &mut usize) -> Vec<Node> {
    let mut out = Vec::new();
    for n in nodes {
        if *k == 0 {
            *k = usize::MAX;
            continue;
        }
        *k = k.wrapping_sub(1);
        match n {
            Node::Group { xf, children } if *k != usize::MAX => {
                let children = without(children, k);
                out.push(Node::Group { xf: *xf, children });
            }
            _ => out.push(n.clone()),
        }
    }
    out
}

/// `exact`'s failures on `desc` at `tol`.
fn exact_failures(desc: &SceneDesc, tol: f64) -> Vec<String> {
    let viewer = viewer_carried(desc.seed);
    let world = World::new(desc, viewer);
    let Some(refs) = reference_parallel(&world) else {
        return Vec::new();
    };
    let text = super::vrml::write(desc);
    let mut out = checks::Outcome {
        tol,
        ..Default::default()
    };
    match checks::library(
        &text,
        desc,
        &checks::options(desc, Integrator::Exact, tol, viewer),
    ) {
        Ok(f) => checks::check_exact(&mut out, desc, &f, &refs, world.light_on_opaque_sphere()),
        Err(e) => out.failures.push(format!("library refused the scene: {e}")),
    }
    out.failures
}

#[test]
#[ignore = "a tool: VERIFY_SEED=S cargo test --test it verify_shrink -- --ignored --nocapture"]
fn verify_shrink() {
    let Some(seed) = std::env::var("VERIFY_SEED")
        .ok()
        .and_then(|s| s.parse().ok())
    else {
        eprintln!("verify_shrink: set VERIFY_SEED");
        return;
    };
    let mut desc = super::generate::scene(seed);
    let tol = super::scene_tol(seed);
    let mut failures = exact_failures(&desc, tol);
    assert!(!failures.is_empty(), "exact does not fail on seed {seed}");
    loop {
        let mut changed = false;
        let mut k = count(&desc.nodes);
        while k > 0 {
            k -= 1;
            let mut trial = desc.clone();
            trial.nodes = without(&desc.nodes, &mut k.clone());
            let f = exact_failures(&trial, tol);
            if !f.is_empty() {
                desc = trial;
                failures = f;
                changed = true;
                k = k.min(count(&desc.nodes));
            }
        }
        if !changed {
            break;
        }
    }
    let file = failures_dir().join(format!("seed-{seed}-shrunk.wrl"));
    let _ = std::fs::create_dir_all(failures_dir());
    std::fs::write(&file, super::vrml::write(&desc)).expect("write the shrunk scene");
    eprintln!(
        "seed {seed}: {} nodes left, tol {tol:e}, written to {}",
        count(&desc.nodes),
        file.display()
    );
    for f in failures.iter().take(8) {
        eprintln!("  {f}");
    }
}
