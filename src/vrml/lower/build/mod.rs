//! The scene builder: it turns expanded nodes into the [`Scene`]. It is told that a node
//! starts (with its type), a field value, that a node-valued field starts or ends, and that a
//! node ends; and, as a shortcut for the commonest node of particle files, a whole sphere
//! node at once ([`sphere`]). It knows nothing of DEF and USE, PROTO and IS, EXTERNPROTO,
//! Inline or ROUTE: the expander (the rest of `lower`) resolves those into plain nodes and
//! drives it; a node the expander records rather than lowers opens a quiet frame here, so
//! that the nesting is kept. Two things it keeps for the expander: an Inline is a grouping
//! node whose `url` it stores (the expander reads the file before the group closes), and
//! what a mesh lowered to is kept under a key the expander gives, so that the expander can
//! have a mesh it has seen delivered again without its events (`mesh`).
//!
//! Grouping nodes remember where their contents start in the IR and, when they close, apply
//! their matrix to that range (VRML allows `translation` after `children`); the same range
//! is the scope of the DirectionalLights among their children.
//!
//! Its parts: `open` (the stack of open nodes), `node` (the node table and what a starting
//! node opens as), `fields` (field values), `close` (closing nodes), `transform` (the
//! Transform matrix and what it moves), `lights` (light scopes), `material` (open Materials
//! and sharing), `mesh` (meshes while they are read), `meshes` (their state), `mesh_shape`
//! (what a closed mesh becomes) and `sphere` (a whole sphere node at once).

pub(super) mod close;
pub(super) mod fields;
pub(super) mod lights;
pub(super) mod material;
pub(super) mod mesh;
pub(super) mod mesh_shape;
pub(super) mod meshes;
pub(super) mod node;
pub(super) mod open;
pub(super) mod sphere;
pub(super) mod transform;

use crate::scene::{Material, Scene};

use close::Bound;
use material::Materials;
use meshes::Meshes;
use open::Open;
use transform::Transforms;

/// The scene being built, and what the nodes open so far hold.
pub(super) struct Builder {
    pub(super) scene: Scene,
    /// The open nodes and node-valued fields (`open`).
    pub(super) open: Open,
    /// Open Materials and the materials met recently (`material`).
    pub(super) materials: Materials,
    /// Transform field boxes for reuse (`transform`).
    pub(super) transforms: Transforms,
    /// Tessellated spheres (`mesh`).
    pub(super) meshes: Meshes,
    /// The first NavigationInfo and Background are bound (`close`).
    pub(super) bound: Bound,
    /// The profile of the gas sphere being built: the Materials lowered meanwhile take it
    /// (the expander sets it for a `GasParticle` instance).
    pub(super) gas_profile: Option<crate::scene::Profile>,
    /// Plain sphere nodes lowered whole (`sphere`).
    pub(super) whole_nodes: u64,
    /// The buffer plain sphere nodes are read into from their text (kept: a node is a few
    /// hundred bytes).
    pub(super) sphere_text: Option<Box<crate::vrml::sphere_node::SphereNode>>,
}

impl Builder {
    pub(super) fn new() -> Self {
        let mut b = Builder {
            scene: Scene::default(),
            open: Open::default(),
            materials: Materials::default(),
            transforms: Transforms::default(),
            meshes: Meshes::default(),
            bound: Bound::default(),
            gas_profile: None,
            whole_nodes: 0,
            sphere_text: None,
        };
        b.materials.unlit = b.scene.materials.add(&Material::unlit());
        b
    }

    /// Names another file read (an Inline, or a file read for its PROTOs): its index in
    /// `Scene::files`, which origins refer to.
    pub(super) fn add_file(&mut self, name: &str) -> usize {
        self.scene.files.push(name.to_string());
        self.scene.files.len() - 1
    }

    /// Opens a file's root: a group of its top-level nodes (the scope of its top-level
    /// DirectionalLights), closed by `close_group_like` when the file ends.
    pub(super) fn open_file_root(&mut self) {
        let root = open::Kind::Group {
            transform: None,
            marks: transform::Marks::of(&self.scene),
            dirlights: None,
            inline_urls: None,
        };
        self.open.push(
            open::Name::Static("<file>"),
            None,
            root,
            crate::source::Pos::at(0),
        );
    }
}
