//! Shrinks a failing scene for a reader: `VERIFY_SEED=S cargo test --test it verify_shrink
//! -- --ignored --nocapture` removes nodes one at a time (lights, shapes, whole groups) for as
//! long as `exact` still fails on the scene, and writes what is left to
//! `target/verify-failures/seed-S-shrunk.wrl` with the failures it still shows.

use super::scenes::{Node, SceneDesc};
use super::{
    check_exact_of, checks, failures_dir, reference_parallel, viewer_carried, world::World,
};

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

/// `nodes` without the node of pre-order index `k` (and what it holds).
fn without(nodes: &[Node], k: usize) -> Vec<Node> {
    /// `seen`: the pre-order index of the next node.
    fn walk(nodes: &[Node], k: usize, seen: &mut usize) -> Vec<Node> {
        let mut out = Vec::new();
        for n in nodes {
            let at = *seen;
            *seen += 1;
            match n {
                _ if at == k => {}
                Node::Group { xf, children } => out.push(Node::Group {
                    xf: *xf,
                    children: walk(children, k, seen),
                }),
                _ => out.push(n.clone()),
            }
        }
        out
    }
    walk(nodes, k, &mut 0)
}

/// `exact`'s failures on `desc` at `tol` (none when the reference outruns its budget).
fn exact_failures(desc: &SceneDesc, tol: f64) -> Vec<String> {
    let world = World::new(desc, viewer_carried(desc.seed));
    let Some(refs) = reference_parallel(&world) else {
        return Vec::new();
    };
    let mut out = checks::Outcome {
        tol,
        ..Default::default()
    };
    check_exact_of(&mut out, desc, &world, &super::vrml::write(desc), &refs);
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
            trial.nodes = without(&desc.nodes, k);
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
