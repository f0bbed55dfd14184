//! The TX language's syntax tree: what a TX text says, before it is
//! lowered onto a material. Numbers are kept as written (colours are
//! display values, sRGB-encoded), optional parameters as present or absent,
//! so that printing a parsed text and parsing it again gives an equal tree.

/// An `r g b` triple as written: display (sRGB-encoded) values.
pub type Rgb = [f32; 3];

/// A coefficient of N3D's `BaseAttributs`, the surface properties a
/// texture sets.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Attr {
    /// `CD`: the diffuse colour.
    Cd,
    /// `CS`: the specular colour.
    Cs,
    /// `CR`: the perfect mirror's coefficient.
    Cr,
    /// `CT`: the transmission coefficient (the light passing through).
    Ct,
    /// `TD`: the diffuse transmission coefficient.
    Td,
}

impl Attr {
    pub const ALL: [Attr; 5] = [Attr::Cd, Attr::Cs, Attr::Cr, Attr::Ct, Attr::Td];

    pub fn keyword(self) -> &'static str {
        match self {
            Attr::Cd => "CD",
            Attr::Cs => "CS",
            Attr::Cr => "CR",
            Attr::Ct => "CT",
            Attr::Td => "TD",
        }
    }

    pub fn from_keyword(word: &str) -> Option<Attr> {
        Attr::ALL.into_iter().find(|a| a.keyword() == word)
    }
}

/// A `BaseAttributs` list: each coefficient at most once, in the order
/// written.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Attrs(pub Vec<(Attr, Rgb)>);

impl Attrs {
    pub fn get(&self, attr: Attr) -> Option<Rgb> {
        self.0.iter().find(|(a, _)| *a == attr).map(|(_, c)| *c)
    }
}

/// One texture of the report's §2.3, closed by its own `FTX`.
#[derive(Debug, Clone, PartialEq)]
pub enum Tex {
    /// `UNI attrs FTX`: the attributes everywhere (`UNI FTX` sets nothing).
    Uni(Attrs),
    /// `QUAD t1 t2 [GU gu] [GV gv] [DEPHASAGE de] FTX`: a checker of
    /// 1/gu × 1/gv cells, `t1` in the even ones; each cell is a whole
    /// texture space for its texture.
    Quad {
        even: Box<Tex>,
        odd: Box<Tex>,
        gu: Option<f32>,
        gv: Option<f32>,
        phase: Option<f32>,
    },
    /// `TUILE DMORTIER d DPENTE p NIV3D n centre mortar-attrs FTX`.
    Tuile {
        mortar_half_width: f32,
        slope_width: f32,
        level: f32,
        centre: Box<Tex>,
        mortar: Attrs,
    },
    /// `MULT t1 … tn FTX`: the textures applied in order.
    Mult(Vec<Tex>),
    /// `IMAGE file attrs FTX`: the image times each attribute's colour.
    Image { file: String, attrs: Attrs },
    /// `DECOUPAGE inside outside NBCOTE n [RAYON r] FTX`.
    Decoupage {
        inside: Box<Tex>,
        outside: Box<Tex>,
        sides: u32,
        radius: Option<f32>,
    },
    /// `NOISE CD1 r g b FREQ f AMPL a FTX`.
    Noise {
        color: Rgb,
        frequency: f32,
        amplitude: f32,
    },
    /// `TURBULENCE CD1 r g b FREQ f AMPL a FTX`.
    Turbulence {
        color: Rgb,
        frequency: f32,
        amplitude: f32,
    },
    /// `BOIS FONCE r g b PALE r g b [RAYON r] [TURB t] FTX`.
    Bois {
        dark: Rgb,
        pale: Rgb,
        ring_width: Option<f32>,
        turbulence: Option<f32>,
    },
    /// `MARBRE CD1 r g b CD2 r g b FREQ f TURB t FREQTURB ft FTX`.
    Marbre {
        dominant: Rgb,
        veins: Rgb,
        frequency: f32,
        turbulence: f32,
        turbulence_frequency: f32,
    },
    /// `BRIQUE brick mortar size_u [size_v] FTX`.
    Brique {
        brick: Box<Tex>,
        mortar: Box<Tex>,
        size_u: f32,
        size_v: Option<f32>,
    },
    /// `VAGUE frequency amplitude FTX`: sines tilting the normal.
    Vague { frequency: f32, amplitude: f32 },
}

/// Which application frame: `ATX … FATX` (a polygon's (u, v)), `APTX …
/// FAPTX` (a plane's) or `ATX3D … FATX3D` (the 3D texture space).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FrameKind {
    Polygon,
    Plane,
    Space,
}

impl FrameKind {
    pub const ALL: [FrameKind; 3] = [FrameKind::Polygon, FrameKind::Plane, FrameKind::Space];

    pub fn opening(self) -> &'static str {
        match self {
            FrameKind::Polygon => "ATX",
            FrameKind::Plane => "APTX",
            FrameKind::Space => "ATX3D",
        }
    }

    pub fn closing(self) -> &'static str {
        match self {
            FrameKind::Polygon => "FATX",
            FrameKind::Plane => "FAPTX",
            FrameKind::Space => "FATX3D",
        }
    }
}

/// An application frame: `origin u v`, nine numbers.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Frame {
    pub origin: [f32; 3],
    pub u: [f32; 3],
    pub v: [f32; 3],
}

impl Tex {
    /// The textures inside this one, in the order the text writes them.
    pub fn children(&self) -> Vec<&Tex> {
        match self {
            Tex::Quad { even, odd, .. } => vec![even, odd],
            Tex::Tuile { centre, .. } => vec![centre],
            Tex::Mult(layers) => layers.iter().collect(),
            Tex::Decoupage {
                inside, outside, ..
            } => vec![inside, outside],
            Tex::Brique { brick, mortar, .. } => vec![brick, mortar],
            Tex::Uni(_)
            | Tex::Image { .. }
            | Tex::Noise { .. }
            | Tex::Turbulence { .. }
            | Tex::Bois { .. }
            | Tex::Marbre { .. }
            | Tex::Vague { .. } => Vec::new(),
        }
    }

    /// The keyword that opens it.
    pub fn keyword(&self) -> &'static str {
        match self {
            Tex::Uni(_) => "UNI",
            Tex::Quad { .. } => "QUAD",
            Tex::Tuile { .. } => "TUILE",
            Tex::Mult(_) => "MULT",
            Tex::Image { .. } => "IMAGE",
            Tex::Decoupage { .. } => "DECOUPAGE",
            Tex::Noise { .. } => "NOISE",
            Tex::Turbulence { .. } => "TURBULENCE",
            Tex::Bois { .. } => "BOIS",
            Tex::Marbre { .. } => "MARBRE",
            Tex::Brique { .. } => "BRIQUE",
            Tex::Vague { .. } => "VAGUE",
        }
    }
}

/// A TX text at the attribute level: optional frames, then the texture.
#[derive(Debug, Clone)]
pub struct Document {
    pub polygon_frame: Option<Frame>,
    pub plane_frame: Option<Frame>,
    pub space_frame: Option<Frame>,
    pub texture: Tex,
    /// Where the text wrote each texture of `texture`: the line and column
    /// of its keyword, in the order the keywords come (the tree's
    /// pre-order), so that lowering can point at a construct the way the
    /// parser points at a word. Empty for a document not read from text;
    /// only the parser fills it, for the tree it read (a tree replaced
    /// afterwards keeps the places of the text).
    pub(super) places: Vec<(usize, usize)>,
}

/// Documents are equal when they say the same thing: where their words
/// were written (`places`) is layout, as blanks are, so a printed document
/// parses back equal.
impl PartialEq for Document {
    fn eq(&self, other: &Self) -> bool {
        self.polygon_frame == other.polygon_frame
            && self.plane_frame == other.plane_frame
            && self.space_frame == other.space_frame
            && self.texture == other.texture
    }
}

impl Document {
    pub fn new(texture: Tex) -> Self {
        Self {
            polygon_frame: None,
            plane_frame: None,
            space_frame: None,
            texture,
            places: Vec::new(),
        }
    }

    /// The line and column where the text wrote `t`, a texture of this
    /// document's tree (the very node, found by address: equal textures
    /// written at two places are two nodes); `None` for a document not
    /// read from text.
    pub fn place_of(&self, t: &Tex) -> Option<(usize, usize)> {
        /// `t`'s index in pre-order below `node`, counting from `next`.
        fn find(node: &Tex, t: &Tex, next: &mut usize) -> Option<usize> {
            if std::ptr::eq(node, t) {
                return Some(*next);
            }
            *next += 1;
            node.children().into_iter().find_map(|c| find(c, t, next))
        }
        let index = find(&self.texture, t, &mut 0)?;
        self.places.get(index).copied()
    }

    pub fn frame(&self, kind: FrameKind) -> Option<&Frame> {
        match kind {
            FrameKind::Polygon => self.polygon_frame.as_ref(),
            FrameKind::Plane => self.plane_frame.as_ref(),
            FrameKind::Space => self.space_frame.as_ref(),
        }
    }

    pub fn frame_mut(&mut self, kind: FrameKind) -> &mut Option<Frame> {
        match kind {
            FrameKind::Polygon => &mut self.polygon_frame,
            FrameKind::Plane => &mut self.plane_frame,
            FrameKind::Space => &mut self.space_frame,
        }
    }
}
