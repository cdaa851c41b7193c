"""Small SVGs, each exercising what a PDF or DXF must keep (200 x 160 px canvases)."""

HEAD = '<svg xmlns="http://www.w3.org/2000/svg" width="200" height="160" viewBox="0 0 100 80">'

CASES = {
    "fills": '<rect x="5" y="5" width="40" height="30" rx="6" fill="#d03020"/>'
             '<circle cx="70" cy="25" r="18" fill="#2060c0"/>'
             '<ellipse cx="50" cy="60" rx="35" ry="12" fill="#30a050"/>'
             '<path d="M10 75 Q30 40 50 75 T90 75 Z" fill="#e0b000"/>',
    "evenodd": '<path fill-rule="evenodd" fill="#402080" d="M10 10h80v60h-80z M30 25h40v30h-40z"/>'
               '<path fill-rule="nonzero" fill="#c04000" d="M50 5 L61 40 L25 18 H75 L39 40 Z"/>',
    "strokes": '<g fill="none" stroke-width="6">'
               '<path d="M10 15 L40 15 L25 35" stroke="#000" stroke-linecap="butt" stroke-linejoin="miter"/>'
               '<path d="M55 15 L85 15 L70 35" stroke="#a00" stroke-linecap="round" stroke-linejoin="round"/>'
               '<path d="M10 50 L40 50 L25 70" stroke="#0a0" stroke-linecap="square" stroke-linejoin="bevel"/>'
               '<path d="M55 70 L70 45 L85 70" stroke="#00a" stroke-miterlimit="1.5"/>'
               '<circle cx="50" cy="40" r="6" stroke="#555" stroke-width="2"/></g>',
    "dashes": '<g fill="none" stroke="#222" stroke-width="3">'
              '<path d="M10 15 H90" stroke-dasharray="8 4"/>'
              '<path d="M10 30 H90" stroke-dasharray="6 3 2" stroke-dashoffset="5"/>'
              '<path d="M10 50 C30 30 70 70 90 50" stroke-dasharray="5" stroke-linecap="round"/>'
              '<rect x="15" y="60" width="70" height="12" stroke-dasharray="10 5"/></g>',
    "gradients": '<defs><linearGradient id="a" x1="0" y1="0" x2="1" y2="0.3">'
                 '<stop offset="0.1" stop-color="#f00"/><stop offset="0.5" stop-color="#ff0"/>'
                 '<stop offset="0.9" stop-color="#00f"/></linearGradient>'
                 '<radialGradient id="b" cx="70" cy="40" r="25" fx="62" fy="35" gradientUnits="userSpaceOnUse">'
                 '<stop offset="0" stop-color="#fff"/><stop offset="0.6" stop-color="#080"/>'
                 '<stop offset="1" stop-color="#004"/></radialGradient>'
                 '<linearGradient id="c" gradientTransform="rotate(30)"><stop offset="0" stop-color="#f80" stop-opacity="0.2"/>'
                 '<stop offset="1" stop-color="#08f"/></linearGradient></defs>'
                 '<rect x="5" y="5" width="45" height="40" fill="url(#a)"/>'
                 '<circle cx="70" cy="40" r="25" fill="url(#b)"/>'
                 '<path d="M5 55 H95 V75 H5 Z" fill="url(#c)" stroke="url(#a)" stroke-width="3"/>',
    "opacity": '<rect x="10" y="10" width="50" height="40" fill="#f00" opacity="0.5"/>'
               '<rect x="40" y="25" width="50" height="40" fill="#00f" fill-opacity="0.6" stroke="#000" '
               'stroke-width="4" stroke-opacity="0.5"/>'
               '<circle cx="30" cy="55" r="18" fill="#0a0" stroke="#ff0" stroke-width="6" opacity="0.6"/>'
               '<g opacity="0.5"><rect x="55" y="5" width="30" height="30" fill="#808"/>'
               '<rect x="65" y="15" width="30" height="30" fill="#088"/></g>',
    "clips": '<defs><clipPath id="one"><circle cx="30" cy="30" r="22"/></clipPath>'
             '<clipPath id="two"><rect x="55" y="5" width="20" height="30"/><circle cx="80" cy="40" r="15"/></clipPath>'
             '<clipPath id="bb" clipPathUnits="objectBoundingBox"><path d="M0 0 H1 L0.5 1 Z"/></clipPath></defs>'
             '<rect x="0" y="0" width="60" height="60" fill="#c33" clip-path="url(#one)"/>'
             '<g clip-path="url(#two)"><rect x="50" y="0" width="50" height="60" fill="#33c"/></g>'
             '<rect x="10" y="55" width="80" height="22" fill="#3a3" clip-path="url(#bb)"/>',
    "transforms": '<g transform="translate(50 40) rotate(25)">'
                  '<rect x="-30" y="-15" width="60" height="30" fill="#468" stroke="#000" stroke-width="2"/>'
                  '<g transform="scale(1.5 0.6) skewX(20)"><circle r="10" fill="#e84"/></g></g>'
                  '<path transform="matrix(0.8 0.2 -0.3 0.9 10 5)" d="M5 5 h20 v20 z" fill="none" '
                  'stroke="#a0a" stroke-width="3" stroke-linejoin="round"/>',
    "masks": '<defs><mask id="m"><rect x="0" y="0" width="100" height="80" fill="#fff"/>'
             '<circle cx="35" cy="40" r="15" fill="#000"/><rect x="60" y="10" width="30" height="60" fill="#808080"/>'
             '</mask><clipPath id="g" clipPathUnits="objectBoundingBox"><circle cx="0.5" cy="0.5" r="0.5"/></clipPath>'
             '</defs>'
             '<rect x="5" y="5" width="90" height="70" fill="#2a6" mask="url(#m)"/>'
             '<g clip-path="url(#g)" opacity="0.8"><rect x="40" y="30" width="20" height="20" fill="#c30"/>'
             '<rect x="50" y="40" width="20" height="20" fill="#03c"/></g>'
             '<circle cx="80" cy="20" r="12" fill="#f0f" style="mix-blend-mode:multiply"/>',
    "dots": '<g stroke="#135" stroke-width="8"><path d="M15 15 Z" stroke-linecap="round"/>'
            '<path d="M35 15 l0 0" stroke-linecap="square"/>'
            '<path d="M75 15 h0 M10 40 H90" stroke-linecap="round"/></g>'
            '<path d="M10 65 L90 60" stroke="#a30" stroke-width="3"/>',  # (its black fill has no area)
}


def svg(name: str) -> str:
    return HEAD + CASES[name] + "</svg>"
